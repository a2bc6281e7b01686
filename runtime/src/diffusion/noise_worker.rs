//! A thread that draws the next noise streams into recycled buffers while the network runs, so a
//! sampling step neither spawns a thread nor allocates. The streams are the same whether they
//! come from the thread or are drawn in place (if the thread cannot be started).

use std::collections::VecDeque;
use std::sync::mpsc;

use ndarray::Array3;

use super::noise::fill_normals;

/// Fills `out` (contiguous, row-major) with stream `stream` of `seed`.
pub(crate) fn fill_noise(seed: u64, stream: u64, out: &mut Array3<f32>) {
    match out.as_slice_mut() {
        Some(values) => fill_normals(seed, stream, values),
        None => {
            let mut values = vec![0f32; out.len()];
            fill_normals(seed, stream, &mut values);
            out.iter_mut().zip(values).for_each(|(o, v)| *o = v);
        }
    }
}

struct Channels {
    requests: mpsc::Sender<(u64, Array3<f32>)>,
    filled: mpsc::Receiver<Array3<f32>>,
}

/// Noise streams asked for ahead and received in the order asked.
pub(crate) struct NoiseWorker {
    seed: u64,
    shape: (usize, usize, usize),
    channels: Option<Channels>,
    /// Streams asked for and not yet received, oldest first; `true` when the thread has it.
    pending: VecDeque<(u64, bool)>,
    spare: Vec<Array3<f32>>,
}

impl NoiseWorker {
    /// Starts the thread (or, if the system refuses one, a worker that draws in place).
    pub(crate) fn start(seed: u64, shape: (usize, usize, usize)) -> NoiseWorker {
        let (requests, jobs) = mpsc::channel::<(u64, Array3<f32>)>();
        let (done, filled) = mpsc::channel();
        let spawned = std::thread::Builder::new()
            .name("sinmdm-noise".into())
            .spawn(move || {
                for (stream, mut buffer) in jobs {
                    fill_noise(seed, stream, &mut buffer);
                    if done.send(buffer).is_err() {
                        break;
                    }
                }
            });
        NoiseWorker {
            seed,
            shape,
            channels: spawned.ok().map(|_| Channels { requests, filled }),
            pending: VecDeque::new(),
            spare: Vec::new(),
        }
    }

    /// A worker that draws every stream on the calling thread when it is received.
    pub(crate) fn in_place(seed: u64, shape: (usize, usize, usize)) -> NoiseWorker {
        NoiseWorker {
            seed,
            shape,
            channels: None,
            pending: VecDeque::new(),
            spare: Vec::new(),
        }
    }

    fn buffer(&mut self) -> Array3<f32> {
        self.spare
            .pop()
            .unwrap_or_else(|| Array3::zeros(self.shape))
    }

    /// Asks for stream `stream`.
    pub(crate) fn request(&mut self, stream: u64) {
        let buffer = self.buffer();
        let sent = match &self.channels {
            Some(c) => c.requests.send((stream, buffer)).is_ok(),
            None => false,
        };
        if !sent {
            self.channels = None;
        }
        self.pending.push_back((stream, sent));
    }

    /// The oldest stream asked for (`None` if none is pending).
    pub(crate) fn receive(&mut self) -> Option<Array3<f32>> {
        let (stream, on_thread) = self.pending.pop_front()?;
        if on_thread && let Some(c) = &self.channels {
            if let Ok(buffer) = c.filled.recv() {
                return Some(buffer);
            }
            self.channels = None;
        }
        let mut buffer = self.buffer();
        fill_noise(self.seed, stream, &mut buffer);
        Some(buffer)
    }

    /// Gives a buffer back for reuse.
    pub(crate) fn recycle(&mut self, buffer: Array3<f32>) {
        self.spare.push(buffer);
    }
}

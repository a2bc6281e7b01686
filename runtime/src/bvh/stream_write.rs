//! A BVH file written a chunk at a time (a stream's motion, hours of it), in flat memory: the
//! header first with the frame count promised, then each chunk's lines. Euler curves stay
//! continuous across chunks. The file appears under its name only when every promised frame is
//! written ([`BvhStreamWriter::finish`]); until then, and if anything fails, it is a temporary
//! file beside it that is removed.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use super::error::{BvhError, BvhErrorKind};
use super::write::{header_text, push_row};
use crate::files::temporary_path;
use crate::motion::clip::LocalMotion;
use crate::motion::skeleton::{Channel, Skeleton};

/// A BVH file being written chunk by chunk.
#[derive(Debug)]
pub struct BvhStreamWriter {
    path: PathBuf,
    temp: PathBuf,
    file: Option<BufWriter<File>>,
    skeleton: Skeleton,
    fps: f64,
    frames: usize,
    written: usize,
    /// The last frame appended (rotations, translations) and its channel values.
    last: Option<(LocalMotion, Vec<f64>)>,
}

impl BvhStreamWriter {
    /// Starts the file at `path` for `frames` frames of `skeleton` at `fps`.
    pub fn create(
        path: impl AsRef<Path>,
        skeleton: &Skeleton,
        fps: f64,
        frames: usize,
    ) -> Result<BvhStreamWriter, BvhError> {
        let path = path.as_ref().to_path_buf();
        let io = |e: std::io::Error| BvhError {
            file: path.display().to_string(),
            line: None,
            kind: BvhErrorKind::Io(e),
        };
        let temp = temporary_path(&path).map_err(io)?;
        let mut file = BufWriter::new(File::create(&temp).map_err(io)?);
        let written = file.write_all(header_text(skeleton, fps, frames).as_bytes());
        let mut writer = BvhStreamWriter {
            path,
            temp,
            file: Some(file),
            skeleton: skeleton.clone(),
            fps,
            frames,
            written: 0,
            last: None,
        };
        written.map_err(|e| writer.fail(e))?;
        Ok(writer)
    }

    fn fail(&mut self, e: std::io::Error) -> BvhError {
        self.file = None;
        let _ = std::fs::remove_file(&self.temp);
        BvhError {
            file: self.path.display().to_string(),
            line: None,
            kind: BvhErrorKind::Io(e),
        }
    }

    fn closed(&self) -> BvhError {
        BvhError {
            file: self.path.display().to_string(),
            line: None,
            kind: BvhErrorKind::Io(std::io::Error::other(
                "an earlier write failed; the file was removed",
            )),
        }
    }

    /// Frames written so far.
    pub fn written(&self) -> usize {
        self.written
    }

    /// Appends the frames of `motion` (the writer's skeleton).
    pub fn append(&mut self, motion: &LocalMotion) -> Result<(), BvhError> {
        let frames = motion.frame_count();
        if self.written + frames > self.frames {
            let e = std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "{} frames would pass the {} promised in the header",
                    self.written + frames,
                    self.frames
                ),
            );
            return Err(self.fail(e));
        }
        if frames == 0 {
            return Ok(());
        }
        let joints = self.skeleton.len();
        // The last frame written leads the chunk, so its Euler curves unwrap from it.
        let mut lead = LocalMotion {
            skeleton: self.skeleton.clone(),
            fps: self.fps,
            rotations: Vec::with_capacity((frames + 1) * joints),
            translations: Vec::with_capacity((frames + 1) * joints),
        };
        if let Some((last, _)) = &self.last {
            lead.rotations.extend_from_slice(&last.rotations);
            lead.translations.extend_from_slice(&last.translations);
        }
        lead.rotations.extend_from_slice(&motion.rotations);
        lead.translations.extend_from_slice(&motion.translations);
        let channels = lead.to_channels();
        let width = self.skeleton.channel_count();
        let skip = usize::from(self.last.is_some());
        // The leading frame's angles differ from what was written for it by whole turns only.
        let mut shift = vec![0.0; width];
        if let Some((_, row)) = &self.last {
            let rotation_columns = self
                .skeleton
                .joints
                .iter()
                .flat_map(|j| j.channels.iter())
                .map(|c| matches!(c, Channel::Rotation(_)));
            for (c, rotates) in rotation_columns.enumerate() {
                if rotates {
                    shift[c] = 360.0 * ((row[c] - channels.frame(0)[c]) / 360.0).round();
                }
            }
        }
        let mut text = String::with_capacity(frames * width * 11);
        let mut row = vec![0.0; width];
        for f in skip..channels.frame_count() {
            for (c, v) in channels.frame(f).iter().enumerate() {
                row[c] = v + shift[c];
            }
            push_row(&mut text, &row);
        }
        let Some(file) = self.file.as_mut() else {
            return Err(self.closed());
        };
        if let Err(e) = file.write_all(text.as_bytes()) {
            return Err(self.fail(e));
        }
        let k = (frames - 1) * joints;
        self.last = Some((
            LocalMotion {
                skeleton: self.skeleton.clone(),
                fps: self.fps,
                rotations: motion.rotations[k..].to_vec(),
                translations: motion.translations[k..].to_vec(),
            },
            row,
        ));
        self.written += frames;
        Ok(())
    }

    /// Completes the file: every promised frame must be written; then it is flushed to disk
    /// and takes its name.
    pub fn finish(mut self) -> Result<(), BvhError> {
        if self.written != self.frames {
            let e = std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "{} frames written of the {} promised",
                    self.written, self.frames
                ),
            );
            return Err(self.fail(e));
        }
        let Some(file) = self.file.take() else {
            return Err(self.closed());
        };
        let done = file
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| f.sync_all())
            .and_then(|()| std::fs::rename(&self.temp, &self.path));
        done.map_err(|e| self.fail(e))
    }
}

impl Drop for BvhStreamWriter {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

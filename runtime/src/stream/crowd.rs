//! Many characters' streams advanced together: a [`Crowd`] steps the characters that need
//! frames in rounds, the most urgent first and within a budget of steps, handing the network
//! their blocks of one window length together.
//!
//! Each character is a [`Stream`] of its own (its own seed, options, steering and supplied
//! poses), and its motion is the same bits as that stream read alone: a block's run does not
//! depend on the runs beside it, since the model runs every sample of a call on its own (one
//! intra-op thread, [`crate::Model`]). Characters join and leave between any two frames.

use ndarray::{Array3, Axis, s};

use super::{Stream, StreamChunk, StreamOptions};
use crate::diffusion::sampler::Denoiser;
use crate::limits::{MAX_CROWD_CHARACTERS, MAX_SAMPLE_FRAMES};
use crate::model_file::ModelMetadata;
use crate::tasks::TaskError;

/// The most blocks one network call of a crowd holds: enough for every thread of a model to
/// have several, few enough that the call's input stays a few megabytes whatever the crowd.
pub const CROWD_CALL_BLOCKS: usize = 16;

/// A character of a [`Crowd`]: the number [`Crowd::join`] gave it, never given again.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct CharacterId(pub u64);

impl std::fmt::Display for CharacterId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "character {}", self.0)
    }
}

/// What one [`Crowd::prepare`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CrowdProgress {
    /// Denoising steps taken, one per character stepped.
    pub steps: usize,
    /// Characters still short of the frames asked for (more steps will make them).
    pub waiting: usize,
}

/// Endless motion for many characters of one model; see the [module documentation](self).
#[derive(Debug)]
pub struct Crowd {
    metadata: ModelMetadata,
    /// The characters in the order they joined.
    characters: Vec<(CharacterId, Stream)>,
    next_id: u64,
    /// The network's input and output of the last call, kept for the next.
    input: Array3<f32>,
    output: Array3<f32>,
}

impl Crowd {
    /// An empty crowd of the model with `metadata` (the [`crate::Model`] it will run on).
    pub fn new(metadata: &ModelMetadata) -> Crowd {
        Crowd {
            metadata: metadata.clone(),
            characters: Vec::new(),
            next_id: 0,
            input: Array3::zeros((0, 0, 0)),
            output: Array3::zeros((0, 0, 0)),
        }
    }

    /// A new character whose motion is a stream with `options` ([`Stream::new`] checks them),
    /// at most [`MAX_CROWD_CHARACTERS`] at once.
    pub fn join(&mut self, options: StreamOptions) -> Result<CharacterId, TaskError> {
        if self.characters.len() >= MAX_CROWD_CHARACTERS {
            return Err(TaskError::Stream(format!(
                "a crowd holds at most {MAX_CROWD_CHARACTERS} characters"
            )));
        }
        let mut stream = Stream::new(&self.metadata, options)?;
        stream.noise_on_this_thread = true;
        let id = CharacterId(self.next_id);
        self.next_id += 1;
        self.characters.push((id, stream));
        Ok(id)
    }

    /// Takes character `id` out of the crowd; its stream goes on alone where the caller keeps
    /// it. `None` if no such character is in the crowd.
    pub fn leave(&mut self, id: CharacterId) -> Option<Stream> {
        let at = self.position(id)?;
        let (_, mut stream) = self.characters.remove(at);
        stream.noise_on_this_thread = false;
        Some(stream)
    }

    /// Characters in the crowd.
    pub fn len(&self) -> usize {
        self.characters.len()
    }

    /// Whether no character is in the crowd.
    pub fn is_empty(&self) -> bool {
        self.characters.is_empty()
    }

    /// The characters, in the order they joined.
    pub fn ids(&self) -> impl Iterator<Item = CharacterId> + '_ {
        self.characters.iter().map(|(id, _)| *id)
    }

    /// Character `id`'s stream (its sizes, frames handed out and ready, warnings).
    pub fn character(&self, id: CharacterId) -> Option<&Stream> {
        self.position(id).map(|at| &self.characters[at].1)
    }

    /// Character `id`'s stream, to steer it ([`Stream::steer`]) or supply its poses
    /// ([`Stream::supply`]); reading it with [`Stream::next`] makes its blocks alone.
    pub fn character_mut(&mut self, id: CharacterId) -> Option<&mut Stream> {
        self.position(id).map(|at| &mut self.characters[at].1)
    }

    fn position(&self, id: CharacterId) -> Option<usize> {
        self.characters.binary_search_by_key(&id, |(c, _)| *c).ok()
    }

    /// Makes frames ahead of need, spending at most `max_steps` denoising steps (one step of
    /// one character each): in rounds, each character with fewer than `ahead` frames ready
    /// takes one step, those with the fewest ready first, all of a round through the network
    /// together. A game calls it every frame with the steps it can afford (its frame budget
    /// over a step's cost), then reads each character's frame, which then never waits.
    pub fn prepare<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        max_steps: usize,
        ahead: usize,
    ) -> Result<CrowdProgress, TaskError>
    where
        TaskError: From<D::Error>,
    {
        self.prepare_among(denoiser, None, max_steps, ahead)
    }

    /// [`Crowd::prepare`] for the characters `ids` only (the others' blocks are not stepped): for
    /// a game that prepares the characters on screen first, or hands out chunks to some
    /// characters only. Numbers not in the crowd are passed over.
    pub fn prepare_characters<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        ids: &[CharacterId],
        max_steps: usize,
        ahead: usize,
    ) -> Result<CrowdProgress, TaskError>
    where
        TaskError: From<D::Error>,
    {
        self.prepare_among(denoiser, Some(ids), max_steps, ahead)
    }

    fn prepare_among<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        among: Option<&[CharacterId]>,
        max_steps: usize,
        ahead: usize,
    ) -> Result<CrowdProgress, TaskError>
    where
        TaskError: From<D::Error>,
    {
        if ahead > MAX_SAMPLE_FRAMES {
            return Err(TaskError::Length {
                frames: ahead,
                reason: format!("at most {MAX_SAMPLE_FRAMES} frames are prepared ahead"),
            });
        }
        let mut steps = 0;
        while steps < max_steps {
            match self.round(denoiser, among, ahead, max_steps - steps)? {
                0 => break,
                taken => steps += taken,
            }
        }
        Ok(CrowdProgress {
            steps,
            waiting: self.short_of(ahead, among).count(),
        })
    }

    /// Every character's next `frames` frames, in the order they joined, making the blocks
    /// that needs together.
    pub fn next<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        frames: usize,
    ) -> Result<Vec<(CharacterId, StreamChunk)>, TaskError>
    where
        TaskError: From<D::Error>,
    {
        super::check_chunk(frames)?;
        while self.round(denoiser, None, frames, usize::MAX)? > 0 {}
        Ok(self
            .characters
            .iter_mut()
            .map(|(id, stream)| (*id, stream.hand_out(frames)))
            .collect())
    }

    /// Characters with fewer than `ahead` frames ready.
    pub fn waiting(&self, ahead: usize) -> usize {
        self.short_of(ahead, None).count()
    }

    /// The places of the characters (of `among`, where given) with fewer than `ahead` frames
    /// ready.
    fn short_of<'a>(
        &'a self,
        ahead: usize,
        among: Option<&'a [CharacterId]>,
    ) -> impl Iterator<Item = usize> + 'a {
        self.characters
            .iter()
            .enumerate()
            .filter(move |(_, (id, s))| {
                s.ready.len() < ahead && among.is_none_or(|ids| ids.contains(id))
            })
            .map(|(at, _)| at)
    }

    /// One step for each character (of `among`, where given) with fewer than `ahead` frames
    /// ready (starting its next block where none is under way), at most `most` of them, the
    /// fewest ready first (then in the order joined); gives the steps taken.
    fn round<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        among: Option<&[CharacterId]>,
        ahead: usize,
        most: usize,
    ) -> Result<usize, TaskError>
    where
        TaskError: From<D::Error>,
    {
        let mut short: Vec<(usize, usize)> = self
            .short_of(ahead, among)
            .map(|at| (self.characters[at].1.ready.len(), at))
            .collect();
        short.sort_unstable();
        short.truncate(most);
        let mut working = Vec::with_capacity(short.len());
        for &(_, at) in &short {
            let (id, stream) = &mut self.characters[at];
            if stream.pending.is_none() {
                let block = stream.start_block().map_err(|e| e.of(*id))?;
                stream.pending = Some(block);
            }
            working.push((stream.pending_frames(), at));
        }
        // Blocks of one window length go through the network together, in the order joined.
        working.sort_unstable();
        for group in working.chunk_by(|a, b| a.0 == b.0) {
            for call in group.chunks(CROWD_CALL_BLOCKS) {
                let members: Vec<usize> = call.iter().map(|&(_, at)| at).collect();
                self.step_together(denoiser, call[0].0, &members)?;
            }
        }
        Ok(working.len())
    }

    /// One step of the blocks under way of the characters at `members` (windows of `frames`
    /// frames each) in one network call; the blocks that finish are turned into frames.
    fn step_together<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        frames: usize,
        members: &[usize],
    ) -> Result<(), TaskError>
    where
        TaskError: From<D::Error>,
    {
        let shape = (members.len(), self.metadata.network.features, frames);
        if self.input.dim() != shape {
            self.input = Array3::zeros(shape);
        }
        let mut t = Vec::with_capacity(members.len());
        for (row, &at) in members.iter().enumerate() {
            let (id, stream) = &mut self.characters[at];
            let sampler = &mut stream.under_way().map_err(|e| e.of(*id))?.sampler;
            t.push(sampler.begin_step().unwrap_or_default());
            self.input
                .index_axis_mut(Axis(0), row)
                .assign(&sampler.current().index_axis(Axis(0), 0));
        }
        if let Err(e) = denoiser.denoise_into(self.input.view(), &t, &mut self.output) {
            for &at in members {
                if let Some(block) = self.characters[at].1.pending.as_mut() {
                    block.sampler.abandon_step();
                }
            }
            return Err(e.into());
        }
        for (row, &at) in members.iter().enumerate() {
            let (id, stream) = &mut self.characters[at];
            let prediction = self.output.slice(s![row..row + 1, .., ..]);
            let sampler = &mut stream.under_way().map_err(|e| e.of(*id))?.sampler;
            sampler
                .finish_step(prediction)
                .map_err(|e| TaskError::Sampler(e).of(*id))?;
            if sampler.is_finished()
                && let Some(block) = stream.pending.take()
            {
                stream.complete_block(block).map_err(|e| e.of(*id))?;
            }
        }
        Ok(())
    }
}

impl Stream {
    /// Frames of the window of the block under way (0 when none is).
    fn pending_frames(&self) -> usize {
        self.pending
            .as_ref()
            .map_or(0, |p| p.sampler.current().dim().2)
    }

    /// The block under way (a crowd steps only blocks it has started).
    fn under_way(&mut self) -> Result<&mut super::block_run::PendingBlock, TaskError> {
        self.pending
            .as_mut()
            .ok_or_else(|| TaskError::Stream("no block of this stream is under way".into()))
    }
}

impl TaskError {
    /// This error, said of character `id`.
    fn of(self, id: CharacterId) -> TaskError {
        TaskError::Character {
            id: id.0,
            source: Box::new(self),
        }
    }
}

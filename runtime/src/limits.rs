//! Every bound the engine puts on what it is given, in one place, each with its reason. Inputs
//! come from games, pipelines and downloaded files; a bound keeps a typo or a hostile file
//! from asking for gigabytes or from overflowing an index, and each is far beyond real use.

/// The longest sample a task makes, and the longest stream chunk or window, in frames (55
/// minutes at 30 fps). Also the longest clip a model file may say it learnt, since a model's
/// default sample is as long as its clip.
pub const MAX_SAMPLE_FRAMES: usize = 100_000;
/// The widest soft border of a task's kept spans, in frames: a border wider than the longest
/// sample would only ever be cut short.
pub const MAX_RAMP_FRAMES: usize = MAX_SAMPLE_FRAMES;
/// The largest crowd one run makes.
pub const MAX_SAMPLES: usize = 1024;
/// The most characters a [`crate::Crowd`] holds at once (each keeps its stream's blocks,
/// about half a megabyte for the shipped walk).
pub const MAX_CROWD_CHARACTERS: usize = 65_536;
/// The largest working set one run may need, in f32 values (1 GiB): `samples x frames x` the
/// larger of `F + 8 C` (the network's layers: F feature rows, C channels) and `12 x joints`
/// (the decoded motion); `tasks::run_values_per_frame` gives the per-frame factor of a model.
pub const MAX_RUN_VALUES: usize = 1 << 28;
/// The longest feature sequence encoding a clip makes, after resampling to the model's frame
/// rate (over nine hours at 30 fps): clips are read whole, so this only stops a frame rate
/// that would blow one up.
pub const MAX_ENCODED_FRAMES: usize = 1_000_000;

/// Most joints a model's skeleton may have.
pub const MAX_JOINTS: usize = 4096;
/// Longest joint name, in bytes.
pub const MAX_NAME_BYTES: usize = 256;
/// Most feature rows F: a 6D rotation and three position channels for every joint.
pub const MAX_FEATURES: usize = 6 * MAX_JOINTS + 3 * MAX_JOINTS;
/// Most network channels C.
pub const MAX_NETWORK_CHANNELS: usize = 8192;
/// Widest QnA window, in frames.
pub const MAX_WINDOW: usize = 255;
/// Most diffusion steps T (the schedule holds a few f64 per step).
pub const MAX_DIFFUSION_STEPS: usize = 100_000;
/// Highest frame rate a model may have.
pub const MAX_FPS: f64 = 10_000.0;

/// The largest model file read, in bytes (2^31 - 1): protobuf's own ceiling, so no valid
/// self-contained ONNX file is larger.
pub const MAX_MODEL_BYTES: u64 = 2_147_483_647;

/// Most threads a model runs samples on at once (each has its own onnxruntime session, a few
/// megabytes): far beyond any machine's cores, and it stops a typo such as `u32::MAX` from
/// asking for that many sessions.
pub const MAX_THREADS: usize = 1024;

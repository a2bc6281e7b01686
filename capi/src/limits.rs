//! The bounds every argument is checked against, as the header's constants (the engine's
//! `sinmdm::limits`, which a test keeps equal). An argument past its bound gets
//! `SINMDM_INVALID_ARGUMENT` and a message naming the argument and the bound.

/// The longest sample a task makes, and the longest stream chunk or block, in frames
/// (`SinmdmPoses.frames`, `frames` of `sinmdm_generate` and `sinmdm_stream_next`, a task's
/// length after expansion).
pub const SINMDM_MAX_SAMPLE_FRAMES: usize = 100_000;
/// The widest soft border (`ramp`) of a task's kept spans, in frames.
pub const SINMDM_MAX_RAMP_FRAMES: usize = 100_000;
/// The largest crowd one run makes (`SinmdmSampling.count`).
pub const SINMDM_MAX_SAMPLES: usize = 1024;
/// The most characters a crowd holds at once (`sinmdm_crowd_join`).
pub const SINMDM_MAX_CROWD_CHARACTERS: usize = 65_536;
/// The largest working set one run may need, in f32 values (1 GiB): a request is refused
/// before anything runs when `count x frames x values` passes it, `values` being what
/// `sinmdm_model_values_per_frame` gives for the model: `max(F + 8 C, 12 x joints)`, with F
/// `SinmdmModelInfo::features` and C the network's channels (64 in the shipped models).
pub const SINMDM_MAX_RUN_VALUES: usize = 1 << 28;
/// The most threads a model runs samples on (`threads` of `sinmdm_model_open*`; 0 = every core).
pub const SINMDM_MAX_THREADS: usize = 1024;
/// The most spans a task takes (`span_count`): each covers at least one frame of at most
/// `SINMDM_MAX_SAMPLE_FRAMES`.
pub const SINMDM_MAX_SPANS: usize = 100_000;
/// The most joint indices a composition takes (`joint_count`, `compose_joint_count`): four times
/// the most joints a skeleton may have (repeats are allowed).
pub const SINMDM_MAX_JOINT_INDICES: usize = 16_384;

/// The largest model `sinmdm_model_open_bytes` takes, in bytes (protobuf's 2 GiB limit on an
/// ONNX file).
pub const SINMDM_MAX_MODEL_BYTES: usize = 2_147_483_647;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_bounds_are_the_engines() {
        use sinmdm::limits;
        assert_eq!(SINMDM_MAX_SAMPLE_FRAMES, limits::MAX_SAMPLE_FRAMES);
        assert_eq!(SINMDM_MAX_RAMP_FRAMES, limits::MAX_RAMP_FRAMES);
        assert_eq!(SINMDM_MAX_SAMPLES, limits::MAX_SAMPLES);
        assert_eq!(SINMDM_MAX_CROWD_CHARACTERS, limits::MAX_CROWD_CHARACTERS);
        assert_eq!(SINMDM_MAX_RUN_VALUES, limits::MAX_RUN_VALUES);
        assert_eq!(SINMDM_MAX_THREADS, limits::MAX_THREADS);
        assert_eq!(SINMDM_MAX_SPANS, limits::MAX_SAMPLE_FRAMES);
        assert_eq!(SINMDM_MAX_JOINT_INDICES, 4 * limits::MAX_JOINTS);
        assert_eq!(SINMDM_MAX_MODEL_BYTES as u64, limits::MAX_MODEL_BYTES);
    }
}

//! The motion representation: skeletons, rotations, forward kinematics, and the feature vector
//! the model learns (SPEC section 2).

pub mod beats;
pub mod bind_pose;
pub mod clip;
pub mod contacts;
pub mod features;
pub mod feet;
pub mod fk;
pub mod ground;
pub mod ik;
pub mod math;
pub mod normalize;
pub mod pose;
pub mod resample;
pub mod rotation;
pub mod skeleton;
pub mod smooth;
pub mod units;
pub mod up;
pub mod up_detect;

pub use beats::{KinematicBeats, kinematic_beats};
pub use clip::{ChannelClip, LocalMotion, fps_from_frame_time};
pub use contacts::ContactConfig;
pub use features::{
    ClipForModel, Column, ColumnKind, EncodeOptions, EncodedClip, FeatureLayout, FeatureMatrix,
    MotionError, RootFeatures, RootLayout, RootStart, decode, decode_from, encode, encode_for,
    encode_for_model, encode_motion, root_track,
};
pub use feet::{Feet, PlantOptions, PlantStats, plant_feet};
pub use fk::{GlobalPose, global_pose, global_poses, max_position_error, skeleton_height};
pub use normalize::{Normalizer, STD_FLOOR_SHARE, STD_FLOOR_SHARE_BEFORE};
pub use pose::{Pose, Quaternion, features_from_poses, motion_from_poses, poses};
pub use skeleton::{Axis, Channel, Joint, Skeleton};
pub use up::UpAxis;
pub use up_detect::{Confidence, UpDetection, choose_up, detect_up};

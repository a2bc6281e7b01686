//! What makes a model current: the clip's bytes, its settings, its training configuration and
//! the code's version, hashed together. A task whose folder holds a model of the same
//! fingerprint trains nothing; any change to one of them makes the model stale.

use sha2::{Digest, Sha256};

use crate::manifest::ClipEntry;

/// The version of the code that trains, recorded in every fingerprint: a new release retrains.
pub const CODE_VERSION: &str = env!("CARGO_PKG_VERSION");

/// The built-in training configuration, for clips that name none.
pub const DEFAULT_CONFIG: &str = include_str!("../../configs/default.yaml");

/// The fingerprint of a clip's task: SHA-256 over the code version, the clip file's bytes, the
/// entry's settings (not its path or name: moving or renaming a clip retrains nothing) and
/// the text of its configuration.
pub fn fingerprint(clip_bytes: &[u8], entry: &ClipEntry, config_text: &str) -> String {
    let settings = ClipEntry {
        clip: Default::default(),
        name: None,
        config: None,
        ..entry.clone()
    };
    sha256_of_parts(&[
        CODE_VERSION.as_bytes(),
        &Sha256::digest(clip_bytes),
        serde_json::to_string(&settings)
            .unwrap_or_default()
            .as_bytes(),
        config_text.as_bytes(),
    ])
}

/// SHA-256 (hex) over `parts`, each preceded by its length (so that moving bytes from one part
/// to the next changes the hash): what the project's fingerprints are made of.
pub fn sha256_of_parts(parts: &[&[u8]]) -> String {
    let mut hash = Sha256::new();
    for part in parts {
        hash.update((part.len() as u64).to_le_bytes());
        hash.update(part);
    }
    hash.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry() -> ClipEntry {
        ClipEntry {
            clip: "a/walk.bvh".into(),
            name: Some("walk".into()),
            animation: None,
            fps: None,
            up: None,
            contacts: None,
            window: None,
            config: None,
        }
    }

    #[test]
    fn clip_settings_and_config_change_it_path_and_name_do_not() {
        let base = fingerprint(b"clip", &entry(), "config");
        assert_eq!(base.len(), 64);
        assert_ne!(base, fingerprint(b"clip2", &entry(), "config"));
        assert_ne!(base, fingerprint(b"clip", &entry(), "config2"));
        let faster = ClipEntry {
            fps: Some(60.0),
            ..entry()
        };
        assert_ne!(base, fingerprint(b"clip", &faster, "config"));
        let moved = ClipEntry {
            clip: "elsewhere/x.bvh".into(),
            name: Some("x".into()),
            ..entry()
        };
        assert_eq!(base, fingerprint(b"clip", &moved, "config"));
    }
}

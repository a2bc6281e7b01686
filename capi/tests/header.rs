//! The committed C header is what cbindgen makes of the crate now, with the crate's own
//! documentation (the conventions in `src/lib.rs`) as the header's introduction. After changing
//! the C ABI, regenerate it with `SINMDM_BLESS=1 cargo test -p sinmdm-c --test header`.

use std::path::{Path, PathBuf};

/// The crate documentation of `src/lib.rs` (its leading `//!` lines) as a C block comment.
fn introduction(crate_dir: &Path) -> String {
    let source = std::fs::read_to_string(crate_dir.join("src/lib.rs")).unwrap();
    let lines: Vec<&str> = source
        .lines()
        .take_while(|l| l.starts_with("//!"))
        .map(|l| {
            l.trim_start_matches("//!")
                .strip_prefix(' ')
                .unwrap_or(l.trim_start_matches("//!"))
        })
        .collect();
    assert!(lines.len() > 20, "src/lib.rs lost its conventions");
    let body: Vec<String> = lines
        .iter()
        .map(|l| {
            assert!(!l.contains("*/"), "a comment end in the introduction: {l}");
            let text = l.replace('`', "");
            if text.is_empty() {
                " *".to_string()
            } else {
                format!(" * {text}")
            }
        })
        .collect();
    format!("/*\n{}\n */", body.join("\n"))
}

/// The status codes as C hosts write them: `SINMDM_OK`, not `SINMDM_STATUS_OK`. In Rust they are
/// `SinmdmStatus::Ok` and so on; cbindgen qualifies each with the whole enum name, and this
/// shortens the qualifier to the library's prefix.
fn short_status_names(generated: &str) -> String {
    const QUALIFIED: &str = "SINMDM_STATUS_";
    let qualified = generated.matches(QUALIFIED).count();
    assert_eq!(
        qualified, 11,
        "the status enum has 11 codes; cbindgen wrote {qualified}"
    );
    generated.replace(QUALIFIED, "SINMDM_")
}

#[test]
fn the_committed_header_is_current() {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).unwrap();
    config.header = Some(introduction(&crate_dir));
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(&crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen could not read the crate")
        .write(&mut generated);
    let generated = short_status_names(&String::from_utf8(generated).unwrap());
    let path = crate_dir.join("include/sinmdm.h");
    if std::env::var_os("SINMDM_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    for promise in [
        "size query",
        "*out to NULL",
        "SINMDM_MAX_",
        "threads",
        "ORT_DYLIB_PATH",
        "CHANGES",
        "SINMDM_VERSION_MAJOR",
        "--error-exitcode=1",
    ] {
        assert!(
            generated.contains(promise),
            "the header's introduction lacks '{promise}'"
        );
    }
    assert!(
        committed == generated,
        "capi/include/sinmdm.h is not what cbindgen makes of capi/src now; regenerate it with \
         SINMDM_BLESS=1 cargo test -p sinmdm-c --test header"
    );
}

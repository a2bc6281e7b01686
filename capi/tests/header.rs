//! The committed C header is what cbindgen makes of the crate now. After changing the C ABI,
//! regenerate it with `SINMDM_BLESS=1 cargo test -p sinmdm-c --test header`.

use std::path::PathBuf;

#[test]
fn the_committed_header_is_current() {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).unwrap();
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(&crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen could not read the crate")
        .write(&mut generated);
    let generated = String::from_utf8(generated).unwrap();
    let path = crate_dir.join("include/sinmdm.h");
    if std::env::var_os("SINMDM_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "capi/include/sinmdm.h is not what cbindgen makes of capi/src now; regenerate it with \
         SINMDM_BLESS=1 cargo test -p sinmdm-c --test header"
    );
}

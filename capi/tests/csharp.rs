//! The C# binding under Mono: `bindings/csharp/*.cs` and the console example
//! `examples/csharp/Example.cs` are compiled with `mcs` (warnings as errors) and run with
//! `mono`; every value must be bit for bit the Rust API's for the same arguments.

mod common;

use std::process::Command;

use common::*;

#[test]
fn the_csharp_default_steps_are_the_c_abis() {
    let source = std::fs::read_to_string(repo().join("bindings/csharp/Sinmdm.cs")).unwrap();
    let declared = format!(
        "public const uint DefaultSteps = {};",
        sinmdm_c::SINMDM_DEFAULT_STEPS
    );
    assert!(source.contains(&declared), "Sinmdm.cs lacks `{declared}`");
    let all = format!(
        "public const uint AllSteps = {};",
        sinmdm_c::SINMDM_ALL_STEPS
    );
    assert!(source.contains(&all), "Sinmdm.cs lacks `{all}`");
}

#[test]
fn the_csharp_binding_gets_the_rust_values_under_mono() {
    let dir = work_dir("csharp");
    let exe = dir.join("example.exe");
    let status = Command::new("mcs")
        .arg("-warnaserror+")
        .arg(format!("-out:{}", exe.display()))
        .args(binding_sources())
        .arg(repo().join("examples/csharp/Example.cs"))
        .status()
        .expect("no C# compiler (mcs): run scripts/setup_tests.sh, which installs mono-mcs");
    assert!(status.success(), "mcs failed");
    let bvh = dir.join("out.bvh");
    let output = Command::new("mono")
        .arg(&exe)
        .arg(model_path())
        .arg(&bvh)
        .arg(steer_model_path())
        .env("LD_LIBRARY_PATH", library_dir())
        .env("ORT_DYLIB_PATH", onnxruntime_path())
        .output()
        .expect("no Mono runtime: run scripts/setup_tests.sh, which installs mono-runtime");
    let stdout = String::from_utf8_lossy(&output.stdout).to_string();
    assert!(
        output.status.success(),
        "the C# example failed ({}): {}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains("info joints=31 root=Hips"), "{stdout}");
    assert!(stdout.contains("unknown joint: status 4"), "{stdout}");
    assert!(
        stdout.contains("tasks expand=52 compose=40 harmonize=40"),
        "{stdout}"
    );
    assert_same_values(&stdout);
    assert_eq!(sinmdm::bvh::read_bvh(&bvh).unwrap().frame_count(), 40);
}

/// The binding's files (`bindings/csharp/*.cs`).
fn binding_sources() -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(repo().join("bindings/csharp"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "cs"))
        .collect();
    files.sort();
    assert!(files.len() >= 2, "{files:?}");
    files
}

/// Compiles `sources` with `mcs` (warnings as errors) into `exe`.
fn compile_csharp(sources: &[std::path::PathBuf], exe: &std::path::Path) {
    let status = Command::new("mcs")
        .arg("-warnaserror+")
        .arg(format!("-out:{}", exe.display()))
        .args(sources)
        .status()
        .expect("no C# compiler (mcs): run scripts/setup_tests.sh, which installs mono-mcs");
    assert!(status.success(), "mcs failed on {sources:?}");
}

#[test]
fn the_csharp_binding_steps_cancels_and_finalizes_under_mono() {
    let dir = work_dir("csharp-checks");
    let exe = dir.join("checks.exe");
    compile_csharp(
        &[
            binding_sources(),
            vec![repo().join("capi/tests/csharp/Checks.cs")],
        ]
        .concat(),
        &exe,
    );
    let output = Command::new("mono")
        .arg(&exe)
        .arg(model_path())
        .env("LD_LIBRARY_PATH", library_dir())
        .env("ORT_DYLIB_PATH", onnxruntime_path())
        .output()
        .expect("no Mono runtime: run scripts/setup_tests.sh, which installs mono-runtime");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success() && stdout.contains(" passed, 0 failed"),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let passed: usize = stdout
        .lines()
        .find_map(|l| l.strip_prefix("csharp checks: "))
        .and_then(|l| l.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    assert!(passed >= 19, "{stdout}");
}

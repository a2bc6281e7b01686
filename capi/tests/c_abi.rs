//! The C ABI through a real C compiler: `tests/c/api_check.c` (and the README's example,
//! `examples/c/generate.c`) are built with the system's `cc` against the shared library, run,
//! and their values compared bit for bit with the Rust API's for the same arguments; the check
//! program also runs under valgrind memcheck, which must find no invalid access and nothing
//! definitely lost.

mod common;

use std::path::Path;
use std::process::Command;

use common::*;

/// Builds a C program with the system compiler, warnings as errors.
fn compile(source: &Path, out: &Path) {
    let lib = library_dir();
    let status = Command::new("cc")
        .args(["-std=c11", "-O1", "-g", "-Wall", "-Wextra", "-Werror"])
        .arg("-I")
        .arg(repo().join("capi/include"))
        .arg(source)
        .arg("-L")
        .arg(&lib)
        .arg("-lsinmdm_c")
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .arg("-o")
        .arg(out)
        .status()
        .expect("no C compiler: run scripts/setup.sh (it installs the test tools)");
    assert!(status.success(), "cc failed on {}", source.display());
}

fn run_check(valgrind: bool) -> String {
    let dir = work_dir(if valgrind { "valgrind" } else { "plain" });
    let exe = dir.join("api_check");
    compile(&repo().join("capi/tests/c/api_check.c"), &exe);
    let not_a_model = dir.join("not_a_model.onnx");
    std::fs::write(&not_a_model, "this is not a model file\n").unwrap();
    let bvh = dir.join("out.bvh");
    let mut command = if valgrind {
        let mut c = Command::new("valgrind");
        c.args([
            "--quiet",
            "--error-exitcode=99",
            "--leak-check=full",
            "--show-leak-kinds=definite",
            "--errors-for-leak-kinds=definite",
        ])
        .arg(format!(
            "--suppressions={}",
            repo().join("capi/tests/c/onnxruntime.supp").display()
        ))
        .arg(&exe);
        c
    } else {
        Command::new(&exe)
    };
    let output = command
        .arg(model_path())
        .arg(&not_a_model)
        .arg(&bvh)
        .env("ORT_DYLIB_PATH", onnxruntime_path())
        .output()
        .expect("could not start the check program (valgrind missing? run scripts/setup.sh)");
    let stdout = String::from_utf8_lossy(&output.stdout).to_string();
    assert!(
        output.status.success(),
        "the C check program failed ({}):\n{}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr),
        stdout
            .lines()
            .filter(|l| l.len() < 200)
            .collect::<Vec<_>>()
            .join("\n")
    );
    // The BVH it wrote is read back by the runtime's reader with the model's skeleton.
    let clip = sinmdm::bvh::read_bvh(&bvh).unwrap();
    assert_eq!(clip.frame_count(), 40);
    stdout
}

#[test]
fn c_program_gets_the_rust_values_and_survives_bad_arguments() {
    let stdout = run_check(false);
    let got = parse(&stdout);
    let want = expected();
    assert_eq!(
        got.keys().collect::<Vec<_>>(),
        want.keys().collect::<Vec<_>>()
    );
    for (label, values) in &want {
        assert!(got[label] == *values, "{label} differs between C and Rust");
    }
    assert!(stdout.contains("info joints=31"), "{stdout}");
    let checks: usize = stdout
        .lines()
        .find_map(|l| l.strip_prefix("bad arguments: "))
        .and_then(|l| l.trim_end_matches(" checks").parse().ok())
        .expect("no bad-argument summary");
    assert!(checks >= 40, "{checks} checks");
}

#[test]
fn c_program_runs_clean_under_valgrind() {
    let stdout = run_check(true);
    assert!(stdout.contains("bad arguments:"), "{stdout}");
}

#[test]
fn the_readme_c_example_builds_and_runs() {
    let dir = work_dir("example");
    let exe = dir.join("generate");
    compile(&repo().join("examples/c/generate.c"), &exe);
    let bvh = dir.join("walk.bvh");
    let output = Command::new(&exe)
        .arg(model_path())
        .arg(&bvh)
        .env("ORT_DYLIB_PATH", onnxruntime_path())
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let clip = sinmdm::bvh::read_bvh(&bvh).unwrap();
    assert_eq!(clip.frame_count(), 120);
}

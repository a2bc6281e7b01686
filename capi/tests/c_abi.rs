//! The C ABI through a real C compiler: `tests/c/api_check.c` (and the README's example,
//! `examples/c/generate.c`) are built with the system's `cc` against the shared library, run,
//! and their values compared bit for bit with the Rust API's for the same arguments; the check
//! program also runs under valgrind memcheck exactly as the header's introduction tells a host
//! to (`--leak-check=full --error-exitcode=1 --suppressions=capi/tests/c/onnxruntime.supp`),
//! and must exit 0: any report the suppression file does not name fails the test. A copy of
//! the check program outside the checkout, where no onnxruntime can be found, checks the
//! refusal's list of places.

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
        .expect("no C compiler: run scripts/setup_tests.sh (it installs the test tools)");
    assert!(status.success(), "cc failed on {}", source.display());
}

/// One report of memcheck: its headline and its stack, innermost frame first.
#[derive(Debug)]
struct Report {
    headline: String,
    frames: Vec<String>,
}

/// The error and leak reports of a memcheck log (summaries, which have no stack, are left out).
fn reports(log: &str) -> Vec<Report> {
    let mut out: Vec<Report> = Vec::new();
    for line in log.lines() {
        let Some(rest) = line.strip_prefix("==").and_then(|l| l.split_once("== ")) else {
            continue;
        };
        let text = rest.1;
        let trimmed = text.trim_start();
        if trimmed.starts_with("at ") || trimmed.starts_with("by ") {
            if let Some(report) = out.last_mut() {
                report.frames.push(trimmed.to_string());
            }
        } else if !text.starts_with(' ') && !text.is_empty() {
            out.push(Report {
                headline: text.to_string(),
                frames: Vec::new(),
            });
        }
    }
    out.retain(|r| !r.frames.is_empty());
    out
}

#[test]
fn the_valgrind_report_reader_finds_each_report_and_its_stack() {
    let log = "==1== Invalid read of size 8\n==1==    at 0x1: strncmp (strcmp-sse2.S:160)\n\
               ==1==    by 0x2: is_dst (dl-load.c:216)\n==1== \n\
               ==1== 40 bytes in 1 blocks are definitely lost in loss record 1 of 2\n\
               ==1==    at 0x3: malloc (in /usr/libexec/valgrind/vgpreload_memcheck-amd64-linux.so)\n\
               ==1==    by 0x4: poses_alloc (api_check.c:59)\n\
               ==1== LEAK SUMMARY:\n==1==    definitely lost: 40 bytes in 1 blocks\n";
    let found = reports(log);
    assert_eq!(found.len(), 2, "{found:?}");
    assert_eq!(found[0].headline, "Invalid read of size 8");
    assert_eq!(found[1].frames.len(), 2);
    assert!(found[1].frames[1].contains("poses_alloc"));
}

/// The memcheck options the header's introduction gives a host, with the suppression file.
fn memcheck_options() -> Vec<String> {
    vec![
        "--leak-check=full".into(),
        "--error-exitcode=1".into(),
        format!(
            "--suppressions={}",
            repo().join("capi/tests/c/onnxruntime.supp").display()
        ),
    ]
}

#[test]
fn the_header_gives_the_memcheck_command_the_test_runs() {
    let header = std::fs::read_to_string(repo().join("capi/include/sinmdm.h")).unwrap();
    let intro: String = header
        .split("*/")
        .next()
        .unwrap()
        .lines()
        .map(|l| l.trim_start_matches(" *").trim())
        .collect::<Vec<_>>()
        .join(" ");
    let checkout = format!("{}/", repo().display());
    let options: Vec<String> = memcheck_options()
        .iter()
        .map(|o| o.replace(&checkout, ""))
        .collect();
    let command = format!("valgrind {}", options.join(" "));
    assert!(
        command.ends_with("--suppressions=capi/tests/c/onnxruntime.supp"),
        "{command}"
    );
    assert!(intro.contains(&command), "the header lacks '{command}'");
}

fn run_check(valgrind: bool) -> String {
    let dir = work_dir(if valgrind { "valgrind" } else { "plain" });
    let exe = dir.join("api_check");
    compile(&repo().join("capi/tests/c/api_check.c"), &exe);
    let not_a_model = dir.join("not_a_model.onnx");
    std::fs::write(&not_a_model, "this is not a model file\n").unwrap();
    let bvh = dir.join("out.bvh");
    let log = dir.join("memcheck.log");
    let mut command = if valgrind {
        let mut c = Command::new("valgrind");
        c.args(memcheck_options())
            .arg(format!("--log-file={}", log.display()))
            .arg(&exe);
        c
    } else {
        Command::new(&exe)
    };
    let output = command
        .arg(model_path())
        .arg(&not_a_model)
        .arg(&bvh)
        .arg(steer_model_path())
        .arg(world_root_model_path())
        .env("ORT_DYLIB_PATH", onnxruntime_path())
        .output()
        .expect("could not start the check program (valgrind missing? run scripts/setup_tests.sh)");
    let stdout = String::from_utf8_lossy(&output.stdout).to_string();
    if valgrind && !output.status.success() {
        let text = std::fs::read_to_string(&log).unwrap_or_default();
        panic!(
            "memcheck with the header's command and suppression file did not exit 0 ({}); \
             reports it did not suppress:\n{:#?}\nstderr: {}\nthe whole log: {}",
            output.status,
            reports(&text),
            String::from_utf8_lossy(&output.stderr),
            log.display()
        );
    }
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
fn without_onnxruntime_the_refusal_names_every_place_searched() {
    // A copy of the check program in a folder outside the checkout, run from there with no
    // ORT_DYLIB_PATH: no folder it searches (its own, the library's, the loader's path, a
    // .venv above it) holds onnxruntime.
    let dir = std::env::temp_dir().join(format!("sinmdm-no-onnxruntime-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let exe = dir.join("api_check");
    compile(&repo().join("capi/tests/c/api_check.c"), &exe);
    let output = Command::new(&exe)
        .arg("--not-found")
        .current_dir(&dir)
        .env_remove("ORT_DYLIB_PATH")
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(
        output.status.success(),
        "{}\n{stdout}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains("not found: 5 places"), "{stdout}");
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

#[test]
fn a_fuzz_of_every_entry_point_never_crashes_nor_fails_inside() {
    let dir = work_dir("fuzz");
    let exe = dir.join("fuzz");
    compile(&repo().join("capi/tests/c/fuzz.c"), &exe);
    let cases = 10_000;
    let output = Command::new(&exe)
        .arg(model_path())
        .arg(steer_model_path())
        .arg(&dir)
        .arg(cases.to_string())
        .env("ORT_DYLIB_PATH", onnxruntime_path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "the fuzz failed ({}): {}\n{stdout}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains(&format!("fuzz: {cases} cases")), "{stdout}");
    // Both successes and every kind of refusal were reached, so the cases were not all alike.
    let count = |status: u32| -> u64 {
        stdout
            .lines()
            .find_map(|l| l.strip_prefix(&format!("status {status}: ")))
            .and_then(|n| n.parse().ok())
            .unwrap_or(0)
    };
    for status in [0, 1, 2, 3, 10] {
        assert!(count(status) > 0, "no call gave status {status}:\n{stdout}");
    }
    assert_eq!(count(9), 0, "{stdout}");
}

//! The C ABI through a real C compiler: `tests/c/api_check.c` (and the README's example,
//! `examples/c/generate.c`) are built with the system's `cc` against the shared library, run,
//! and their values compared bit for bit with the Rust API's for the same arguments; the check
//! program also runs under valgrind memcheck with no suppression file, and no report may come
//! from the project's code (the C program, the library): the reports valgrind makes inside
//! glibc's loader and onnxruntime are listed by name, and any other report fails the test.

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

/// Where a report comes from: the first frame that is not memcheck's own replacement of an
/// allocator or a string routine, read as glibc's loader, onnxruntime, or anything else.
fn origin(report: &Report) -> &'static str {
    let skipped = [
        "vgpreload_memcheck",
        "strcmp-sse2",
        "strncmp",
        "memcpy",
        "malloc",
        "calloc",
        "realloc",
    ];
    let frame = report
        .frames
        .iter()
        .find(|f| !skipped.iter().any(|s| f.contains(s)))
        .map_or("", String::as_str);
    if frame.contains("dl-load.c") || frame.contains("dl-open.c") || frame.contains("ld-linux") {
        "glibc's dynamic loader"
    } else if frame.contains("libonnxruntime") {
        "onnxruntime"
    } else {
        "the project"
    }
}

#[test]
fn the_valgrind_report_reader_tells_ours_from_theirs() {
    let log = "==1== Invalid read of size 8\n==1==    at 0x1: strncmp (strcmp-sse2.S:160)\n\
               ==1==    by 0x2: is_dst (dl-load.c:216)\n==1== \n\
               ==1== 40 bytes in 1 blocks are definitely lost in loss record 1 of 2\n\
               ==1==    at 0x3: malloc (in /usr/libexec/valgrind/vgpreload_memcheck-amd64-linux.so)\n\
               ==1==    by 0x4: poses_alloc (api_check.c:59)\n\
               ==1== LEAK SUMMARY:\n==1==    definitely lost: 40 bytes in 1 blocks\n";
    let found = reports(log);
    assert_eq!(found.len(), 2, "{found:?}");
    assert_eq!(origin(&found[0]), "glibc's dynamic loader");
    assert_eq!(origin(&found[1]), "the project");
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
        c.args([
            "--leak-check=full",
            "--show-leak-kinds=definite",
            "--errors-for-leak-kinds=definite",
            "--num-callers=40",
        ])
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
    if valgrind {
        let text = std::fs::read_to_string(&log).unwrap();
        let found = reports(&text);
        let ours: Vec<&Report> = found
            .iter()
            .filter(|r| origin(r) == "the project")
            .collect();
        assert!(
            ours.is_empty(),
            "memcheck reports from the project's code:\n{ours:#?}\nthe whole log: {}",
            log.display()
        );
        for report in &found {
            eprintln!(
                "third-party report ({}): {}",
                origin(report),
                report.headline
            );
        }
    }
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

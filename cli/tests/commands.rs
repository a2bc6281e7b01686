//! The `sinmdm` command line as a user runs it: the binary, real files, real onnxruntime.

use sinmdm_eval::Report;

/// A small valid clip (shared with the runtime's BVH tests): two joints, two frames.
const VALID: &str = include_str!("../../tests/data/two_joints.bvh");

fn repo_file(relative: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

fn test_model() -> std::path::PathBuf {
    std::env::var_os("SINMDM_TEST_MODEL")
        .map(Into::into)
        .unwrap_or_else(|| repo_file("tests/data/models/walk_tiny.onnx"))
}

fn sinmdm(args: &[&std::ffi::OsStr]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_sinmdm"))
        .args(args)
        .output()
        .expect("run sinmdm")
}

#[test]
fn cli_reports_bad_input_and_writes_no_partial_output() {
    let dir = std::env::temp_dir().join(format!("sinmdm-bad-input-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.bvh");
    std::fs::write(&bad, VALID.replace("Frames: 2", "Frames: 3")).unwrap();
    let out = dir.join("out.bvh");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_sinmdm"))
        .args([
            "inspect",
            bad.to_str().unwrap(),
            "--roundtrip",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("bad.bvh:20: truncated MOTION block"),
        "{stderr}"
    );
    assert!(!out.exists());
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_sinmdm"))
        .args(["inspect", bad.to_str().unwrap(), "--fps", "0"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&run.stderr).contains("--fps must be a positive number"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn eval_command_prints_the_table_and_writes_json() {
    let dir = std::env::temp_dir().join(format!("sinmdm-eval-{}", std::process::id()));
    let json = dir.join("scores.json");
    let model = test_model();
    let clip = repo_file("tests/data/bvh/human_walk_cmu_131_01.bvh");
    let out = sinmdm(&[
        "eval".as_ref(),
        "-m".as_ref(),
        model.as_os_str(),
        "--clip".as_ref(),
        clip.as_os_str(),
        "--samples".as_ref(),
        "3".as_ref(),
        "--steps".as_ref(),
        "4".as_ref(),
        "--quiet".as_ref(),
        "--json".as_ref(),
        json.as_os_str(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for row in [
        "| coverage (%) ↑ |",
        "| global diversity ↑ |",
        "| local diversity ↑ |",
        "| inter diversity ↑ |",
        "| intra diversity diff ↓ |",
        "| harmonic mean ↑ |",
    ] {
        assert!(stdout.contains(row), "missing {row} in\n{stdout}");
    }
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(value["format"], "sinmdm-eval");
    assert_eq!(value["samples"], 3);
    // Twice the clip: 249 frames at 30 fps.
    assert_eq!(value["frames"], 498);
    let report: Report = serde_json::from_value(value["report"].clone()).unwrap();
    assert_eq!(report.per_sample.len(), 3);
    assert_eq!(report.sample_frames, 498);
    assert!((0.0..=100.0).contains(&report.coverage.mean));
    assert!((0.0..=1.0).contains(&report.harmonic_mean));
    assert!(report.global_diversity.mean.is_finite() && report.global_diversity.mean >= 0.0);
    // One share per 30-frame window of the clip; the stretches printed are the rare ones.
    assert_eq!(report.clip_window_coverage.len(), 249 - 30 + 1);
    let rare = report.rarely_made(50.0);
    if rare.is_empty() {
        assert!(
            stdout.contains("every 30-frame window of the clip"),
            "{stdout}"
        );
    }
    for stretch in rare {
        let frames = format!(
            "frames {}:{} (",
            stretch.first_frame,
            stretch.last_frame + 1
        );
        assert!(stdout.contains(&frames), "missing {frames} in\n{stdout}");
    }
    // The raw motion as written and the planted motion are scored too, for the same samples.
    for key in ["raw_motion_report", "planted_report"] {
        let other: Report = serde_json::from_value(value[key].clone()).unwrap();
        assert_eq!(other.per_sample.len(), 3, "{key}");
        assert_eq!(other.sample_frames, 498, "{key}");
    }
    assert!(stdout.contains("planting's cost"), "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn eval_command_refuses_bad_input_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("sinmdm-eval-bad-{}", std::process::id()));
    let json = dir.join("scores.json");
    let model = test_model();
    let walk = repo_file("tests/data/bvh/human_walk_cmu_131_01.bvh");
    let fox = repo_file("tests/data/bvh/fox_survey_khronos.bvh");
    let cases: [(&[&std::ffi::OsStr], &str); 3] = [
        (
            &[
                "--clip".as_ref(),
                walk.as_os_str(),
                "--samples".as_ref(),
                "0".as_ref(),
            ],
            "--samples must be at least 1",
        ),
        (
            &["--clip".as_ref(), fox.as_os_str()],
            "skeleton differs from the model's",
        ),
        (
            &[
                "--clip".as_ref(),
                walk.as_os_str(),
                "--frames".as_ref(),
                "12".as_ref(),
                "--steps".as_ref(),
                "2".as_ref(),
            ],
            "--frames must be at least 30",
        ),
    ];
    for (extra, message) in cases {
        let mut args: Vec<&std::ffi::OsStr> = vec![
            "eval".as_ref(),
            "-m".as_ref(),
            model.as_os_str(),
            "--quiet".as_ref(),
            "--json".as_ref(),
            json.as_os_str(),
        ];
        args.extend_from_slice(extra);
        let out = sinmdm(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{extra:?} was accepted");
        assert!(stderr.contains(message), "{extra:?}: {stderr}");
        assert!(!json.exists(), "{extra:?} left {}", json.display());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

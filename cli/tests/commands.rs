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
    // The walk's first pose held for 2 s: a clip in which nothing moves.
    std::fs::create_dir_all(&dir).unwrap();
    let still = dir.join("still.bvh");
    let text = std::fs::read_to_string(&walk).unwrap();
    let (hierarchy, motion) = text.split_once("MOTION").unwrap();
    let mut lines = motion.lines().skip_while(|l| !l.starts_with("Frame Time"));
    let time = lines.next().unwrap();
    let pose = lines.next().unwrap();
    let frames: String = std::iter::repeat_n(format!("{pose}\n"), 240).collect();
    std::fs::write(
        &still,
        format!("{hierarchy}MOTION\nFrames: 240\n{time}\n{frames}"),
    )
    .unwrap();
    let cases: [(&[&std::ffi::OsStr], &str); 4] = [
        (
            &["--clip".as_ref(), still.as_os_str()],
            "nothing moves in the clip",
        ),
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
    // A task's reference is held to the same rule.
    let out = dir.join("ib.bvh");
    let args: Vec<&std::ffi::OsStr> = vec![
        "inbetween".as_ref(),
        "-m".as_ref(),
        model.as_os_str(),
        "--reference".as_ref(),
        still.as_os_str(),
        "--keep".as_ref(),
        "0:1s".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
        "--quiet".as_ref(),
    ];
    let done = sinmdm(&args);
    let stderr = String::from_utf8_lossy(&done.stderr);
    assert!(
        !done.status.success() && stderr.contains("nothing moves in the clip"),
        "{stderr}"
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs `sinmdm` with string arguments and returns (success, stdout, stderr).
fn run_text(args: &[&str]) -> (bool, String, String) {
    let os: Vec<&std::ffi::OsStr> = args.iter().map(std::ffi::OsStr::new).collect();
    let out = sinmdm(&os);
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Asserts that the `encode` output of a BVH clip and of its GLB have the same columns, and 6D
/// rotations that agree to f32 rounding.
fn assert_same_rotations(bvh: &serde_json::Value, glb: &serde_json::Value) {
    let values = |v: &serde_json::Value| -> Vec<f64> {
        v["samples"][0]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|row| row.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
            .collect()
    };
    assert_eq!(bvh["columns"], glb["columns"]);
    let (a, b) = (values(bvh), values(glb));
    assert_eq!(a.len(), b.len());
    // 6D rotations agree to f32 rounding; root travel is in metres against CMU units, so the
    // comparison is of rotations (columns with "rot6d").
    let columns: Vec<String> = bvh["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    let frames = a.len() / columns.len();
    for (c, name) in columns.iter().enumerate() {
        if !name.contains("rot6d") {
            continue;
        }
        for f in 0..frames {
            let (x, y) = (a[c * frames + f], b[c * frames + f]);
            assert!((x - y).abs() < 1e-5, "{name} frame {f}: {x} against {y}");
        }
    }
}

#[test]
fn every_command_that_reads_a_clip_reads_gltf_and_names_what_it_refuses() {
    let dir = std::env::temp_dir().join(format!("sinmdm-gltf-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let model = test_model();
    let model = model.to_str().unwrap();
    let walk = repo_file("tests/data/bvh/human_walk_cmu_131_01.bvh");
    let walk = walk.to_str().unwrap();
    let (ok, _, err) = run_text(&["convert", walk, "-o", &path("walk.glb")]);
    assert!(ok, "{err}");
    // The same clip as BVH and as GLB encodes to the same features in the model's layout.
    for (clip, json) in [
        (walk.to_string(), "bvh.json"),
        (path("walk.glb"), "glb.json"),
    ] {
        let (ok, _, err) = run_text(&["encode", &clip, "-m", model, "-o", &path(json)]);
        assert!(ok, "{err}");
    }
    let read = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join(name)).unwrap()).unwrap()
    };
    let (bvh, glb) = (read("bvh.json"), read("glb.json"));
    assert_same_rotations(&bvh, &glb);
    // inspect, render, reorient and a task's reference take the GLB.
    let (ok, out, err) = run_text(&["inspect", &path("walk.glb")]);
    assert!(
        ok && out.contains("animations 1") && out.contains("joints     31"),
        "{out}{err}"
    );
    let (ok, _, err) = run_text(&["render", &path("walk.glb"), "-o", &path("walk.png")]);
    assert!(ok && dir.join("walk.png").is_file(), "{err}");
    let (ok, _, err) = run_text(&[
        "reorient",
        &path("walk.glb"),
        "--to",
        "z",
        "-o",
        &path("z.bvh"),
    ]);
    assert!(ok, "{err}");
    let (ok, _, err) = run_text(&[
        "inbetween",
        "-m",
        model,
        "--reference",
        &path("walk.glb"),
        "--keep",
        "0:1s",
        "--keep",
        "2s:",
        "--steps",
        "3",
        "-o",
        &path("ib.glb"),
        "--quiet",
    ]);
    assert!(ok && dir.join("ib.glb").is_file(), "{err}");
    // Refusals name the file and the problem; nothing is written.
    let (ok, _, err) = run_text(&["inspect", &path("walk.glb"), "--clip-anim", "Run"]);
    assert!(
        !ok && err.contains("walk.glb") && err.contains("no animation named 'Run'"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_fbx_clip_is_read_and_what_the_commands_refuse_is_named() {
    let dir = std::env::temp_dir().join(format!("sinmdm-fbx-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let walk = repo_file("tests/data/bvh/human_walk_cmu_131_01.bvh");
    let walk = walk.to_str().unwrap();
    // Refusals name the file and the problem; nothing is written.
    std::fs::write(dir.join("clip.fbx"), b"Kaydara FBX Binary").unwrap();
    let (ok, _, err) = run_text(&["inspect", &path("clip.fbx")]);
    assert!(
        !ok && err.contains("clip.fbx") && err.contains("not an FBX file"),
        "{err}"
    );
    // An FBX clip: its stack listed, its bones without their namespace, and BVH or GLB out.
    let mixamo = repo_file("tests/data/fbx/human_walk_cmu_131_01_mixamo_style.fbx");
    let mixamo = mixamo.to_str().unwrap();
    let (ok, out, err) = run_text(&["inspect", mixamo]);
    assert!(
        ok && out.contains("animations 1")
            && out.contains("'mixamo.com' (#0) 1.00 s")
            && out.contains("joints     31 (7 End Sites)")
            && out.contains("up         +Y"),
        "{out}{err}"
    );
    let (ok, _, err) = run_text(&["convert", mixamo, "-o", &path("mixamo.glb")]);
    assert!(ok && dir.join("mixamo.glb").is_file(), "{err}");
    let (ok, _, err) = run_text(&["inspect", mixamo, "--clip-anim", "1"]);
    assert!(!ok && err.contains("no animation stack 1"), "{err}");
    let (ok, _, err) = run_text(&["convert", walk, "-o", &path("walk.fbx")]);
    assert!(
        !ok && err.contains("FBX") && !dir.join("walk.fbx").exists(),
        "{err}"
    );
    let (ok, _, err) = run_text(&["convert", walk, "-o", &path("walk.bvh"), "--proxy-mesh"]);
    assert!(
        !ok && err.contains("--proxy-mesh is for glTF output"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn dance_and_beats_name_what_they_refuse_and_write_nothing() {
    let dir = std::env::temp_dir().join(format!("sinmdm-dance-refusals-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = repo_file("onnx-models/human_dance_rokoko.onnx");
    let clip = repo_file("tests/data/bvh/human_dance_rokoko_jesse.bvh");
    let out = dir.join("dance.bvh");
    let used = dir.join("used.json");
    let base = |bpm: &str| {
        vec![
            "dance".to_string(),
            "-m".into(),
            model.to_str().unwrap().into(),
            "--reference".into(),
            clip.to_str().unwrap().into(),
            "--bpm".into(),
            bpm.into(),
            "--seconds".into(),
            "6".into(),
            "--steps".into(),
            "4".into(),
            "-o".into(),
            out.to_str().unwrap().into(),
            "--quiet".into(),
        ]
    };
    // At 20 BPM every beat is 3.1x the clip's beat, every other one 6.2x and half beats 1.55x:
    // refused, naming the ratio and the trained range.
    let args = base("20");
    let (ok, _, err) = run_text(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        !ok && err.contains("0.75-1.25") && err.contains("--bpm"),
        "{err}"
    );
    assert!(!out.exists());
    // A beat file with a time that goes back names its line.
    let beats = dir.join("beats.txt");
    std::fs::write(&beats, "0.5\n1.0\n0.9\n").unwrap();
    let mut args = base("120");
    let at = args.iter().position(|a| a == "--bpm").unwrap();
    args.splice(
        at..at + 2,
        ["--beats".to_string(), beats.to_str().unwrap().into()],
    );
    let (ok, _, err) = run_text(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(!ok && err.contains("beats.txt, line 3"), "{err}");
    assert!(!out.exists());
    // A good dance records the beats it used: keyframes on every other beat of 124 BPM.
    let mut args = base("124");
    args.extend(["--beats-out".into(), used.to_str().unwrap().into()]);
    let (ok, stdout, err) = run_text(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(ok, "{err}");
    assert!(stdout.contains("Beat Align Score"), "{stdout}");
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&used).unwrap()).unwrap();
    assert_eq!(record["level"], "every-other");
    assert_eq!(record["frames"], 180);
    assert!(out.exists());
    // A song that is not there is named; a missing --music is asked for.
    let (ok, _, err) = run_text(&["beats", "no/such/song.wav"]);
    assert!(!ok && err.contains("no/such/song.wav"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn steer_takes_facings_and_names_what_it_refuses() {
    let dir = std::env::temp_dir().join(format!("sinmdm-steer-face-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let zombie = repo_file("onnx-models/human_zombie_walk_fair.onnx");
    let zombie = zombie.to_str().unwrap();
    let out = dir.join("out.bvh");
    let out_text = out.to_str().unwrap();
    // A path with a facing per line: along +X, facing +Y (the zombie's file is +Z up).
    let path = dir.join("path.csv");
    let lines: Vec<String> = (0..90)
        .map(|i| format!("{},0,0,0,1,0", 0.3 * f64::from(i)))
        .collect();
    std::fs::write(&path, format!("x,y,z,fx,fy,fz\n{}\n", lines.join("\n"))).unwrap();
    let path_text = path.to_str().unwrap();
    let (ok, stdout, stderr) = run_text(&[
        "steer", "-m", zombie, "--path", path_text, "--steps", "5", "-o", out_text, "--report",
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("facing off the commanded one by"),
        "{stdout}"
    );
    assert!(stdout.contains("path distance"), "{stdout}");
    std::fs::remove_file(&out).unwrap();
    // Refusals name the flag or the line, and write nothing.
    let refusals: [(&[&str], &str); 5] = [
        (
            &["--path", path_text, "--face", "1,0,0"],
            "give one or the other",
        ),
        (&["--face", "0,0,1"], "no part on the ground"),
        (&["--face", "1,0"], "--face takes three"),
        (&["--face", "1,0,0", "--velocity", path_text], "--velocity"),
        (&["--path", path_text, "--face", "1,nan,0"], "--face"),
    ];
    for (flags, said) in refusals {
        let mut args = vec!["steer", "-m", zombie, "--steps", "5", "-o", out_text];
        args.extend_from_slice(flags);
        let (ok, _, stderr) = run_text(&args);
        assert!(!ok, "{flags:?} was taken");
        assert!(stderr.contains(said), "{flags:?}: {stderr}");
        assert!(!out.exists(), "{flags:?} wrote {out_text}");
    }
    std::fs::write(&path, "1,0,0,0,1\n2,0,0,0,1\n").unwrap();
    let (ok, _, stderr) = run_text(&["steer", "-m", zombie, "--path", path_text, "-o", out_text]);
    assert!(!ok);
    assert!(
        stderr.contains("line 1") && stderr.contains("six"),
        "{stderr}"
    );
    assert!(!out.exists());
}

//! The README's engine snippet (docs/readme_engine_snippet.rs, the README's code block line for
//! line) compiles against the engine API and runs: a change to the API that breaks the README
//! breaks this build. A test also checks that the README still holds the snippet.

fn readme_engine_snippet() -> Result<Vec<sinmdm::Pose>, Box<dyn std::error::Error>> {
    include!("../../../docs/readme_engine_snippet.rs")
}

#[test]
fn the_readme_snippet_runs_and_gives_ten_seconds_of_poses() {
    // Its paths are the repository root's, where the README's commands run.
    std::env::set_current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).unwrap();
    sinmdm::init_onnxruntime().expect("run scripts/setup.sh first");
    let poses = readme_engine_snippet().unwrap();
    assert_eq!(poses.len(), 300);
    assert!(poses.iter().all(|p| p.rotations.len() == 31));
}

#[test]
fn the_readme_shows_the_snippet_line_for_line() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let readme = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    let snippet = std::fs::read_to_string(format!("{root}/docs/readme_engine_snippet.rs")).unwrap();
    // The block between the file's outer braces (its first line `{` and its last line `}`).
    let lines: Vec<&str> = snippet.lines().collect();
    let open = lines.iter().position(|l| *l == "{").unwrap();
    let close = lines.iter().rposition(|l| *l == "}").unwrap();
    let body = &lines[open + 1..close];
    assert!(body.len() > 10, "{body:?}");
    let block = format!("```rust\n{}\n```", body.join("\n"));
    assert!(
        readme.contains(&block),
        "README.md's engine block differs from docs/readme_engine_snippet.rs"
    );
}

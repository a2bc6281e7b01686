//! Bad FBX files get an error naming the file and the part at fault, never a panic: each kind
//! of problem on its own (edits of the Mixamo-style ASCII fixture), then random mutations of the
//! ASCII text and of Blender's binary file.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;

use sinmdm_formats::fbx::read_fbx;
use sinmdm_formats::{AnimationChoice, ReadOptions, read_clip};

mod common;
use common::{Rng, fbx_fixture, root};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sinmdm-bad-fbx-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn mixamo_text() -> String {
    std::fs::read_to_string(root().join("tests/data/fbx/human_walk_cmu_131_01_mixamo_style.fbx"))
        .unwrap()
}

/// Reads `bytes` written as `name`; the error's text, or the frame count when it reads.
fn read(bytes: &[u8], name: &str, options: &ReadOptions) -> Result<usize, String> {
    let path = scratch(name);
    std::fs::write(&path, bytes).unwrap();
    let result = read_fbx(&path, options);
    std::fs::remove_file(&path).unwrap();
    result
        .map(|read| read.clip.frame_count())
        .map_err(|e| e.to_string())
}

fn error(bytes: &[u8], name: &str) -> String {
    match read(bytes, name, &ReadOptions::default()) {
        Ok(frames) => panic!("{name} was read ({frames} frames)"),
        Err(message) => {
            assert!(message.contains(name), "{message} does not name the file");
            message
        }
    }
}

/// The fixture as it is reads, so each edit below is what fails.
#[test]
fn the_unedited_fixture_reads() {
    let text = mixamo_text();
    assert_eq!(
        read(text.as_bytes(), "fine.fbx", &ReadOptions::default()),
        Ok(31)
    );
}

/// Files that are not FBX, or are damaged or cut short, are refused as such.
#[test]
fn files_that_are_not_sound_fbx_are_named() {
    let text = mixamo_text();
    // Not FBX at all, and an empty file.
    let message = error(b"solid cube\nendsolid cube\n", "not_fbx.fbx");
    assert!(message.contains("not an FBX file"), "{message}");
    assert!(error(b"", "empty.fbx").contains("it is empty"));
    // A binary header and nothing sound after it, and the ASCII file cut short: said plainly,
    // and the reader's own words once.
    let message = error(
        b"Kaydara FBX Binary  \x00\x1a\x00\xe8\x1c\x00\x00",
        "cut.fbx",
    );
    assert!(
        message.contains("binary FBX header") && message.contains("damaged or cut short"),
        "{message}"
    );
    assert_eq!(message.matches("Failed to load").count(), 1, "{message}");
    // Found by scripts/fuzz.sh: Blender's walk with one array's declared length mutated, which
    // asked for 640 MB from a 218 KB file; the memory a load may take follows the file's size.
    let mut found = Vec::new();
    std::io::Read::read_to_end(
        &mut flate2::read::GzDecoder::new(
            std::fs::File::open(root().join("tests/data/fbx/fuzz_oom_array.fbx.gz")).unwrap(),
        ),
        &mut found,
    )
    .unwrap();
    let message = error(&found, "fuzz_oom_array.fbx");
    assert!(
        message.contains("asks for more than the 70 MB"),
        "{message}"
    );
    let message = error(&text.as_bytes()[..text.len() / 3], "half.fbx");
    assert!(
        message.contains("cut short") || message.contains("damaged"),
        "{message}"
    );
}

/// A file with no bones, or with two skeletons, is refused as such.
#[test]
fn a_missing_or_split_skeleton_is_named() {
    let text = mixamo_text();
    // No bones: every limb node made a plain null.
    let message = error(
        text.replace("\"LimbNode\" {", "\"Null\" {").as_bytes(),
        "no_bones.fbx",
    );
    assert!(message.contains("no bones"), "{message}");

    // Two skeletons side by side: the toes' chain cut loose from the hips.
    let left_hip = text
        .lines()
        .find(|l| l.contains("Model::mixamorig:LHipJoint"))
        .map(|l| l.trim().split(['\t', ' ', ',']).nth(1).unwrap().to_string())
        .unwrap();
    let hips = text
        .lines()
        .find(|l| l.contains("Model::mixamorig:Hips"))
        .map(|l| l.trim().split(['\t', ' ', ',']).nth(1).unwrap().to_string())
        .unwrap();
    let cut = text.replace(
        &format!("C: \"OO\",{left_hip},{hips}"),
        &format!("C: \"OO\",{left_hip},0"),
    );
    assert_ne!(cut, text);
    let message = error(cut.as_bytes(), "two_roots.fbx");
    assert!(
        message.contains("2 root bones") && message.contains("LHipJoint"),
        "{message}"
    );
}

/// A file with no animation stack, or without the one asked for, is refused as such.
#[test]
fn a_missing_animation_stack_is_named() {
    let text = mixamo_text();
    // No animation stack.
    let start = text.find("\tAnimationStack:").unwrap();
    let end = start + text[start..].find("\n\t}\n").unwrap() + 4;
    let message = error(
        format!("{}{}", &text[..start], &text[end..]).as_bytes(),
        "no_stack.fbx",
    );
    assert!(message.contains("no animation stack"), "{message}");

    // A stack that is not there by name or index, with the ones that are.
    let by_name = ReadOptions {
        animation: Some(AnimationChoice::Name("Run".into())),
        fps: None,
    };
    let message = read(text.as_bytes(), "no_run.fbx", &by_name).unwrap_err();
    assert!(
        message.contains("'Run'") && message.contains("mixamo.com"),
        "{message}"
    );
    let by_index = ReadOptions {
        animation: Some(AnimationChoice::Index(3)),
        fps: None,
    };
    let message = read(text.as_bytes(), "no_3.fbx", &by_index).unwrap_err();
    assert!(message.contains("no animation stack 3"), "{message}");
}

/// A frame rate that is no rate, or that makes the clip too long, is refused as such.
#[test]
fn a_bad_frame_rate_is_named() {
    let text = mixamo_text();
    // A frame rate that is no rate, and one that makes the clip absurdly long.
    let zero_fps = ReadOptions {
        animation: None,
        fps: Some(0.0),
    };
    let message = read(text.as_bytes(), "zero_fps.fbx", &zero_fps).unwrap_err();
    assert!(message.contains("frame rate"), "{message}");
    let huge_fps = ReadOptions {
        animation: None,
        fps: Some(1e7),
    };
    let message = read(text.as_bytes(), "huge_fps.fbx", &huge_fps).unwrap_err();
    assert!(message.contains("--fps"), "{message}");
}

/// A bone with a non-uniform scale is refused as such.
#[test]
fn a_non_uniform_scale_is_named() {
    let text = mixamo_text();
    // A bone squashed by a non-uniform scale.
    let squashed = text.replacen(
        "P: \"Lcl Scaling\", \"Lcl Scaling\", \"\", \"A\",1,1,1",
        "P: \"Lcl Scaling\", \"Lcl Scaling\", \"\", \"A\",1,0.5,1",
        3,
    );
    let message = error(squashed.as_bytes(), "squashed.fbx");
    assert!(message.contains("scale"), "{message}");
}

/// A stack with no declared time range still reads.
#[test]
fn a_stack_with_no_time_range_reads() {
    let text = mixamo_text();
    // A stack that declares no time range is read from its first key to its last.
    let no_range: String = text
        .lines()
        .filter(|l| !l.contains("LocalStart") && !l.contains("ReferenceStart"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(
        read(no_range.as_bytes(), "no_range.fbx", &ReadOptions::default()),
        Ok(31)
    );
}

/// FBX bytes under another extension are refused by name.
#[test]
fn another_extension_is_refused_by_name() {
    let text = mixamo_text();
    // The extension decides: FBX bytes under another name are refused by name.
    let path = scratch("walk.fbz");
    std::fs::write(&path, text.as_bytes()).unwrap();
    let message = read_clip(&path, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("walk.fbz") && message.contains(".fbx"),
        "{message}"
    );
    std::fs::remove_file(path).unwrap();
}

/// `bytes` with a few random edits: bytes overwritten, a run deleted, or the tail cut off.
fn mutate(bytes: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut out = bytes.to_vec();
    for _ in 0..1 + rng.below(4) {
        match rng.below(4) {
            0 | 1 => {
                let at = rng.below(out.len());
                out[at] = rng.next() as u8;
            }
            2 => {
                let at = rng.below(out.len());
                let len = rng.below(64).min(out.len() - at);
                out.drain(at..at + len);
            }
            _ => {
                let keep = rng.below(out.len());
                out.truncate(keep.max(1));
            }
        }
    }
    out
}

#[test]
fn random_mutations_give_errors_never_panics() {
    let ascii = mixamo_text().into_bytes();
    let binary = std::fs::read(fbx_fixture("fox_survey_khronos_armature.fbx")).unwrap();
    let mut rng = Rng(0x5EED_F8B0);
    let (mut read_fine, mut refused) = (0, 0);
    for case in 0..600 {
        let source = if case % 2 == 0 { &ascii } else { &binary };
        let bytes = mutate(source, &mut rng);
        let name = format!("mutant_{case}.fbx");
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            read(&bytes, &name, &ReadOptions::default())
        }));
        match outcome {
            Ok(Ok(_)) => read_fine += 1,
            Ok(Err(message)) => {
                assert!(message.contains(&name), "case {case}: {message}");
                refused += 1;
            }
            Err(_) => panic!("case {case} panicked"),
        }
    }
    // Both outcomes happen: the mutations reach past the header.
    assert!(
        read_fine > 0 && refused > 0,
        "{read_fine} read, {refused} refused"
    );
}

#[test]
fn a_still_first_stack_is_passed_over_and_marked() {
    // As Mixamo serves a download: a still 'Take 001' before the motion.
    let text = mixamo_text().replacen(
        "\tAnimationStack: 100001,",
        "\tAnimationStack: 900001, \"AnimStack::Take 001\", \"\" {\n\t}\n\tAnimationLayer: 900002, \"AnimLayer::BaseLayer\", \"\" {\n\t}\n\tAnimationStack: 100001,",
        1,
    );
    let text = text.replacen(
        "\tC: \"OO\",100002,100001",
        "\tC: \"OO\",900002,900001\n\tC: \"OO\",100002,100001",
        1,
    );
    let path = scratch("take_001_first.fbx");
    std::fs::write(&path, &text).unwrap();
    let read = read_fbx(&path, &ReadOptions::default()).unwrap();
    let names: Vec<_> = read.animations.iter().map(|a| a.name.clone()).collect();
    assert_eq!(
        names,
        [Some("Take 001".to_string()), Some("mixamo.com".to_string())]
    );
    assert_eq!(read.animation.name.as_deref(), Some("mixamo.com"));
    let still: Vec<_> = read.animations.iter().map(|a| a.still).collect();
    assert_eq!(still, [Some(true), Some(false)]);
    // Asked for by name, the still stack is read, and says it is still.
    let take = ReadOptions {
        animation: Some(AnimationChoice::Name("Take 001".into())),
        fps: None,
    };
    let read = read_fbx(&path, &take).unwrap();
    assert_eq!(read.animation.still, Some(true));
    assert!(!sinmdm_formats::clip_moves(&read.clip));
    std::fs::remove_file(&path).unwrap();
}

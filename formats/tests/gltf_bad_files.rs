//! Bad glTF files get an error naming the file and the part at fault, never a panic: each kind
//! of problem on its own, then 2 000 random mutations of real files (JSON fields and buffer
//! bytes).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use sinmdm::bvh::read_bvh;
use sinmdm::motion::UpAxis;
use sinmdm_formats::gltf::container::{Asset, glb_bytes, parse_glb};
use sinmdm_formats::gltf::{GltfWriteOptions, gltf_document, read_gltf};
use sinmdm_formats::{FileAccess, ReadOptions, read_clip_with_access};

mod common;
use common::Rng;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sinmdm-bad-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The fox, cut to its first 12 frames, as a glTF document and its binary buffer.
fn fox() -> (Value, Vec<u8>) {
    let mut motion = read_bvh(root().join("tests/data/bvh/fox_survey_khronos.bvh"))
        .unwrap()
        .to_local();
    let keep = 12 * motion.skeleton.len();
    motion.rotations.truncate(keep);
    motion.translations.truncate(keep);
    let options = GltfWriteOptions {
        up: UpAxis::PosY,
        metres_per_unit: 0.01,
        proxy_mesh: false,
    };
    gltf_document(&[("Survey".into(), &motion)], &options).unwrap()
}

/// Reads `json` + `bin` as a GLB file; the error's text, or `None` when it reads.
fn read(json: &Value, bin: &[u8], name: &str) -> Option<String> {
    let path = scratch(name);
    std::fs::write(&path, glb_bytes(json, bin)).unwrap();
    let result = read_gltf(&path, &ReadOptions::default());
    std::fs::remove_file(&path).unwrap();
    result.err().map(|e| e.to_string())
}

fn error(json: &Value, bin: &[u8], name: &str) -> String {
    read(json, bin, name).unwrap_or_else(|| panic!("{name} was read"))
}

#[test]
fn the_unmodified_file_reads() {
    let (json, bin) = fox();
    assert_eq!(read(&json, &bin, "fine.glb"), None);
}

#[test]
fn each_problem_is_named_with_the_file_and_the_part() {
    let (json, bin) = fox();
    let mut no_skin = json.clone();
    no_skin.as_object_mut().unwrap().remove("skins");
    let message = error(&no_skin, &bin, "no_skin.glb");
    assert!(
        message.contains("no_skin.glb") && message.contains("has no skin"),
        "{message}"
    );

    let mut no_animation = json.clone();
    no_animation.as_object_mut().unwrap().remove("animations");
    let message = error(&no_animation, &bin, "no_animation.glb");
    assert!(message.contains("has no animation"), "{message}");

    let mut moves_nothing = json.clone();
    for channel in moves_nothing["animations"][0]["channels"]
        .as_array_mut()
        .unwrap()
    {
        channel["target"]["node"] = json!(9999);
    }
    let message = error(&moves_nothing, &bin, "still.glb");
    assert!(
        message.contains("animation 0 ('Survey')") && message.contains("moves no joint"),
        "{message}"
    );

    // A sampler whose output has fewer values than its input has keys.
    let mut short = json.clone();
    let output = short["animations"][0]["samplers"][0]["output"]
        .as_u64()
        .unwrap() as usize;
    short["accessors"][output]["count"] = json!(5);
    let message = error(&short, &bin, "short.glb");
    assert!(
        message.contains("animation 0, sampler 0") && message.contains("12 keys but 5"),
        "{message}"
    );

    // A buffer cut short: the accessors run past its end.
    let message = error(&json, &bin[..bin.len() / 2], "cut.glb");
    assert!(
        message.contains("buffer 0") && message.contains("truncated"),
        "{message}"
    );

    // NaN in the key times (a float written over the first key).
    let input = json["animations"][0]["samplers"][0]["input"]
        .as_u64()
        .unwrap() as usize;
    let view = json["accessors"][input]["bufferView"].as_u64().unwrap() as usize;
    let at = json["bufferViews"][view]["byteOffset"]
        .as_u64()
        .unwrap_or(0) as usize;
    let mut nan = bin.clone();
    nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let message = error(&json, &nan, "nan.glb");
    assert!(
        message.contains(&format!("accessor {input}")) && message.contains("NaN"),
        "{message}"
    );

    // Key times that go backwards, a scaled joint, two roots.
    let mut backwards = bin.clone();
    backwards[at + 4..at + 8].copy_from_slice(&(-1.0f32).to_le_bytes());
    let message = error(&json, &backwards, "backwards.glb");
    assert!(message.contains("do not increase"), "{message}");
    let mut scaled = json.clone();
    scaled["nodes"][3]["scale"] = json!([2.0, 2.0, 2.0]);
    let message = error(&scaled, &bin, "scaled.glb");
    assert!(
        message.contains("node 3") && message.contains("unit scale"),
        "{message}"
    );
    let mut two_roots = json.clone();
    let children = two_roots["nodes"][0]["children"]
        .as_array()
        .unwrap()
        .clone();
    two_roots["nodes"][0]["children"] = json!([children[0]]);
    let message = error(&two_roots, &bin, "two_roots.glb");
    assert!(message.contains("root joints"), "{message}");

    // Not a motion file at all.
    let path = scratch("text.glb");
    std::fs::write(&path, b"glTF and nothing else").unwrap();
    let message = read_gltf(&path, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("text.glb") && message.contains("GLB"),
        "{message}"
    );
    std::fs::remove_file(path).unwrap();
}

/// The fox with the last key of every sampler moved to `seconds`: a few keys far apart.
fn last_key_at(seconds: f32) -> (Value, Vec<u8>) {
    let (json, mut bin) = fox();
    for sampler in json["animations"][0]["samplers"].as_array().unwrap() {
        let input = sampler["input"].as_u64().unwrap() as usize;
        let accessor = &json["accessors"][input];
        let view = &json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
        let at = view["byteOffset"].as_u64().unwrap_or(0) as usize
            + accessor["byteOffset"].as_u64().unwrap_or(0) as usize
            + 4 * (accessor["count"].as_u64().unwrap() as usize - 1);
        bin[at..at + 4].copy_from_slice(&seconds.to_le_bytes());
    }
    (json, bin)
}

#[test]
fn a_few_keys_far_apart_cannot_make_the_reader_sample_for_long() {
    // 12 keys a bone: to 100 s the reader samples 3 000 frames (66 000 transforms, under
    // MAX_SPARSE_TRANSFORMS); to 1 000 s, 30 000 frames from a file of a few kilobytes.
    let (json, bin) = last_key_at(100.0);
    assert_eq!(read(&json, &bin, "far_100.glb"), None);
    let (json, bin) = last_key_at(1000.0);
    let message = error(&json, &bin, "far_1000.glb");
    assert!(
        message.contains("far_1000.glb")
            && message.contains("MAX_SPARSE_TRANSFORMS")
            && message.contains("--fps"),
        "{message}"
    );
    // The input the glTF fuzz target found (31 KB): a key moved to 522 s, 12 544 frames of 22
    // joints, which took the reader 0.8 s before the bound.
    let found = root().join("tests/data/gltf/fuzz_far_keys.glb");
    let message = read_gltf(&found, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(message.contains("MAX_SPARSE_TRANSFORMS"), "{message}");
}

/// Every path to a value inside `value`.
fn paths(value: &Value, at: Vec<Value>, out: &mut Vec<Vec<Value>>) {
    out.push(at.clone());
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                let mut next = at.clone();
                next.push(json!(k));
                paths(v, next, out);
            }
        }
        Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                let mut next = at.clone();
                next.push(json!(i));
                paths(v, next, out);
            }
        }
        _ => {}
    }
}

/// The value at `path`, if an earlier mutation left it there.
fn at<'a>(value: &'a mut Value, path: &[Value]) -> Option<&'a mut Value> {
    path.iter().try_fold(value, |v, key| match key {
        Value::String(k) => v.get_mut(k.as_str()),
        Value::Number(i) => v.get_mut(i.as_u64()? as usize),
        _ => None,
    })
}

/// A hostile replacement for a JSON value.
fn hostile(rng: &mut Rng, old: &Value) -> Value {
    let numbers = [
        json!(-1),
        json!(0),
        json!(1),
        json!(3),
        json!(1e30),
        json!(-1e30),
        json!(4_294_967_295u64),
        json!(18_446_744_073_709_551_615u64),
        json!(0.5),
        json!(1e-30),
    ];
    match rng.below(6) {
        0 => numbers[rng.below(numbers.len())].clone(),
        1 => Value::Null,
        2 => json!("CUBICSPLINE"),
        3 => json!([]),
        4 => json!({}),
        _ => match old {
            Value::Number(n) => json!(n.as_f64().unwrap_or(0.0) + (rng.below(5) as f64 - 2.0)),
            Value::Array(a) if !a.is_empty() => json!(a[..rng.below(a.len())].to_vec()),
            _ => json!(true),
        },
    }
}

#[test]
fn two_thousand_mutated_files_give_errors_never_a_panic() {
    let (json, bin) = fox();
    let mut all = Vec::new();
    paths(&json, Vec::new(), &mut all);
    let mut rng = Rng(0x5eed);
    let mut outcomes = [0usize; 2];
    for case in 0..2000 {
        let (mut mutated, mut bytes) = (json.clone(), bin.clone());
        for _ in 0..1 + rng.below(3) {
            match rng.below(4) {
                0 | 1 => {
                    let path = &all[1 + rng.below(all.len() - 1)];
                    if let Some(target) = at(&mut mutated, path) {
                        *target = hostile(&mut rng, target);
                    }
                }
                2 => {
                    let i = rng.below(bytes.len());
                    bytes[i] = rng.next() as u8;
                }
                _ => {
                    let i = rng.below(bytes.len());
                    let v = [f32::NAN, f32::INFINITY, -1.0, 1e30, 0.0][rng.below(5)];
                    let end = (i + 4).min(bytes.len());
                    bytes[i..end].copy_from_slice(&v.to_le_bytes()[..end - i]);
                }
            }
        }
        let mut glb = glb_bytes(&mutated, &bytes);
        if rng.below(10) == 0 {
            glb.truncate(rng.below(glb.len()));
        }
        let path = scratch(&format!("case{case}.glb"));
        std::fs::write(&path, &glb).unwrap();
        let result = catch_unwind(AssertUnwindSafe(|| {
            read_gltf(&path, &ReadOptions::default())
        }));
        std::fs::remove_file(&path).unwrap();
        match result {
            Err(_) => panic!("case {case} panicked: {mutated}"),
            Ok(Ok(read)) => {
                outcomes[0] += 1;
                assert!(read.clip.frame_count() > 0);
            }
            Ok(Err(e)) => {
                outcomes[1] += 1;
                assert!(e.to_string().contains(&format!("case{case}.glb")), "{e}");
            }
        }
    }
    // Both outcomes occur: the mutations are neither all harmless nor all fatal.
    assert!(outcomes[0] > 100 && outcomes[1] > 100, "{outcomes:?}");
    // The container parser on its own, with every truncation of a small file.
    let small = glb_bytes(&json!({"asset": {"version": "2.0"}}), &[1, 2, 3]);
    for end in 0..small.len() {
        let _: Result<Asset, _> = parse_glb(Path::new("t.glb"), &small[..end]);
    }
}

/// A folder of its own for one test's files, emptied first.
fn folder(name: &str) -> PathBuf {
    let dir = scratch(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The fox as a `.gltf` file in `dir` whose one buffer is `uri` of `byte_length` bytes; the
/// buffer's true bytes are returned for writing where the URI points.
fn side_car_gltf(dir: &Path, uri: &str, byte_length: u64) -> (PathBuf, Vec<u8>) {
    let (mut json, bin) = fox();
    json["buffers"][0]["uri"] = json!(uri);
    json["buffers"][0]["byteLength"] = json!(byte_length);
    let path = dir.join("clip.gltf");
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    (path, bin)
}

fn gltf_error(path: &Path, access: FileAccess) -> String {
    match read_clip_with_access(path, &ReadOptions::default(), access) {
        Ok(_) => panic!("{} was read", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn side_car_buffers_must_be_relative_regular_files_in_the_folder() {
    let dir = folder("side_cars");
    let open = FileAccess {
        allow_outside_folder: true,
    };
    // Devices: refused before a byte is read, whatever the byteLength.
    let (path, _) = side_car_gltf(&dir, "/dev/zero", 95_396);
    let message = gltf_error(&path, open);
    assert!(
        message.contains("clip.gltf") && message.contains("'/dev/zero'"),
        "{message}"
    );
    let (path, _) = side_car_gltf(&dir, "/dev/zero", 8_000_000_000);
    let message = gltf_error(&path, open);
    assert!(message.contains("MAX_GLTF_BUFFER_BYTES"), "{message}");
    // Absolute paths, file: and other schemes are refused by name, opted in or not.
    let secret = folder("secret");
    let (_, bin) = side_car_gltf(&dir, "x", 0);
    std::fs::write(secret.join("hidden.bin"), &bin).unwrap();
    let absolute = secret.join("hidden.bin").display().to_string();
    for uri in [
        absolute.clone(),
        format!("file://{absolute}"),
        "https://example.com/hidden.bin".into(),
    ] {
        let (path, _) = side_car_gltf(&dir, &uri, bin.len() as u64);
        let message = gltf_error(&path, open);
        assert!(
            message.contains(&format!("'{uri}'")) && message.contains("relative"),
            "{message}"
        );
    }
    // A relative path out of the folder reads only when asked.
    let (path, _) = side_car_gltf(&dir, "../secret/hidden.bin", bin.len() as u64);
    let message = gltf_error(&path, FileAccess::default());
    assert!(
        message.contains("'../secret/hidden.bin'") && message.contains("--allow-outside-folder"),
        "{message}"
    );
    read_clip_with_access(&path, &ReadOptions::default(), open).unwrap();
    // And so does a symbolic link in the folder that leads out of it.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(secret.join("hidden.bin"), dir.join("link.bin")).unwrap();
        let (path, _) = side_car_gltf(&dir, "link.bin", bin.len() as u64);
        let message = gltf_error(&path, FileAccess::default());
        assert!(
            message.contains("outside the glTF file's folder"),
            "{message}"
        );
        read_clip_with_access(&path, &ReadOptions::default(), open).unwrap();
    }
    // In the folder it reads, and no more than byteLength is taken from a longer file.
    let mut longer = bin.clone();
    longer.extend_from_slice(&[0; 1000]);
    std::fs::write(dir.join("fox.bin"), &longer).unwrap();
    let (path, _) = side_car_gltf(&dir, "fox.bin", bin.len() as u64);
    read_clip_with_access(&path, &ReadOptions::default(), FileAccess::default()).unwrap();
    // A file shorter than its byteLength, a huge byteLength and a directory are named.
    let (path, _) = side_car_gltf(&dir, "fox.bin", longer.len() as u64 + 1);
    let message = gltf_error(&path, FileAccess::default());
    assert!(message.contains("truncated"), "{message}");
    let (path, _) = side_car_gltf(&dir, "fox.bin", 8_000_000_000);
    let message = gltf_error(&path, FileAccess::default());
    assert!(
        message.contains("buffer 0") && message.contains("MAX_GLTF_BUFFER_BYTES"),
        "{message}"
    );
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let (path, _) = side_car_gltf(&dir, "sub", 4);
    let message = gltf_error(&path, FileAccess::default());
    assert!(message.contains("not a regular file"), "{message}");
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&secret).unwrap();
}

#[cfg(unix)]
#[test]
fn a_fifo_is_refused_without_waiting_for_a_writer() {
    let dir = folder("fifo");
    let fifo = dir.join("pipe.bin");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    if !made {
        eprintln!("mkfifo is not available; skipped");
        return;
    }
    let (path, _) = side_car_gltf(&dir, "pipe.bin", 16);
    let message = gltf_error(&path, FileAccess::default());
    assert!(message.contains("not a regular file"), "{message}");
    // The clip file itself, too.
    let clip = dir.join("pipe.glb");
    std::fs::rename(&fifo, &clip).unwrap();
    let message = gltf_error(&clip, FileAccess::default());
    assert!(message.contains("not a regular file"), "{message}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_default_animation_is_the_first_that_moves() {
    let motion = read_bvh(root().join("tests/data/bvh/fox_survey_khronos.bvh"))
        .unwrap()
        .to_local();
    let joints = motion.skeleton.len();
    let mut still = motion.clone();
    still.rotations = still.rotations[..joints].repeat(4);
    still.translations = still.translations[..joints].repeat(4);
    let options = GltfWriteOptions {
        up: UpAxis::PosY,
        metres_per_unit: 0.01,
        proxy_mesh: false,
    };
    let (json, bin) = gltf_document(
        &[("Take 001".into(), &still), ("mixamo.com".into(), &motion)],
        &options,
    )
    .unwrap();
    let path = scratch("still_first.glb");
    std::fs::write(&path, glb_bytes(&json, &bin)).unwrap();
    let read = read_gltf(&path, &ReadOptions::default()).unwrap();
    assert_eq!(read.animation.name.as_deref(), Some("mixamo.com"));
    assert_eq!(read.animations[0].still, Some(true));
    assert_eq!(read.animations[1].still, Some(false));
    std::fs::remove_file(&path).unwrap();
}

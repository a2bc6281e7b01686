//! Model files that cannot crash the host: 2 100 (300 of each class; `SINMDM_FUZZ_CASES` for a
//! longer run) mutated copies of the small trained walk model (metadata fields replaced,
//! deleted, duplicated, set to hostile values; graph bytes flipped and truncated; the graph's
//! interface renamed or retyped) are opened and, when they open, run and decoded through the
//! library. Each must be refused with an error, naming the field for metadata, or work: never
//! a panic, an allocation past the limit, or a hang. The counts per class are printed
//! (`--nocapture`).

use std::alloc::{GlobalAlloc, Layout, System};
use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::panic::AssertUnwindSafe;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use onnx_protobuf::ModelProto;
use protobuf::Message;
use serde_json::Value;
use sinmdm::diffusion::noise::mix;
use sinmdm::model_file::{METADATA_KEY, MetadataError};
use sinmdm::{Model, ModelError, ModelOptions, Request, Task};

/// Records the largest single allocation of the process.
struct Largest;

static LARGEST: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Largest = Largest;

/// No mutant may make the runtime allocate more than this at once (the run asked for is tiny).
const ALLOCATION_LIMIT: usize = 256 << 20;
/// Nor take longer than this to open, run and decode.
const TIME_LIMIT: Duration = Duration::from_secs(20);

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(1);
        mix(self.0)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

#[derive(Clone, Debug)]
enum PathPart {
    Key(String),
    Index(usize),
}

/// Every value of a JSON tree by path.
fn paths(v: &Value, at: Vec<PathPart>, out: &mut Vec<Vec<PathPart>>) {
    out.push(at.clone());
    match v {
        Value::Object(map) => map.iter().for_each(|(k, c)| {
            let mut p = at.clone();
            p.push(PathPart::Key(k.clone()));
            paths(c, p, out)
        }),
        Value::Array(items) => items.iter().enumerate().for_each(|(i, c)| {
            let mut p = at.clone();
            p.push(PathPart::Index(i));
            paths(c, p, out)
        }),
        _ => {}
    }
}

fn at<'a>(v: &'a mut Value, path: &[PathPart]) -> &'a mut Value {
    path.iter().fold(v, |v, part| match part {
        PathPart::Key(k) => &mut v[k.as_str()],
        PathPart::Index(i) => &mut v[*i],
    })
}

fn hostile(rng: &mut Rng, old: &Value) -> Value {
    let n = old.as_f64().unwrap_or(1.0);
    match rng.below(14) {
        0 => Value::from(-1),
        1 => Value::from(0),
        2 => Value::from(u64::MAX),
        3 => Value::from(1u64 << 40),
        4 => Value::from(1e308),
        5 => Value::from(-1e308),
        6 => Value::from(n * 2.0 + 1.0),
        7 => Value::from(n + 1.0),
        8 => Value::Null,
        9 => Value::from("x"),
        10 => Value::Array(vec![]),
        11 => Value::Object(Default::default()),
        12 => Value::from(true),
        _ => Value::from(rng.below(100_000) as u64),
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Class {
    ValueReplaced,
    KeyDeleted,
    ElementDuplicated,
    NonFiniteText,
    GraphBytesFlipped,
    GraphTruncated,
    InterfaceChanged,
}

const CLASSES: [Class; 7] = [
    Class::ValueReplaced,
    Class::KeyDeleted,
    Class::ElementDuplicated,
    Class::NonFiniteText,
    Class::GraphBytesFlipped,
    Class::GraphTruncated,
    Class::InterfaceChanged,
];

fn with_metadata(original: &ModelProto, text: String) -> Vec<u8> {
    let mut model = original.clone();
    for entry in model.metadata_props.iter_mut() {
        if entry.key == METADATA_KEY {
            entry.value = text.clone();
        }
    }
    model.write_to_bytes().unwrap()
}

/// A mutated copy of the model's bytes, and what was done.
fn mutant(original: &ModelProto, json: &Value, class: Class, rng: &mut Rng) -> (Vec<u8>, String) {
    let mut all = Vec::new();
    paths(json, Vec::new(), &mut all);
    match class {
        Class::ValueReplaced | Class::KeyDeleted | Class::ElementDuplicated => {
            let mut v = json.clone();
            let path = all[1 + rng.below(all.len() - 1)].clone();
            let (last, parent) = path.split_last().unwrap();
            let what = match class {
                Class::ValueReplaced => {
                    let target = at(&mut v, &path);
                    *target = hostile(rng, target);
                    format!("{path:?} = {target}")
                }
                Class::KeyDeleted => {
                    match (at(&mut v, parent), last) {
                        (Value::Object(map), PathPart::Key(k)) => {
                            map.remove(k);
                        }
                        (Value::Array(items), PathPart::Index(i)) => {
                            items.remove(*i);
                        }
                        _ => {}
                    }
                    format!("deleted {path:?}")
                }
                _ => {
                    if let (Value::Array(items), PathPart::Index(i)) = (at(&mut v, parent), last) {
                        let copy = items[*i].clone();
                        items.insert(*i, copy);
                    }
                    format!("duplicated {path:?}")
                }
            };
            (with_metadata(original, v.to_string()), what)
        }
        Class::NonFiniteText => {
            // JSON has no NaN or infinity: put the tokens a careless writer would in place of a
            // number, or cut the text short.
            let text = json.to_string();
            let digits: Vec<usize> = text
                .char_indices()
                .filter(|(_, c)| c.is_ascii_digit())
                .map(|(i, _)| i)
                .collect();
            let i = digits[rng.below(digits.len())];
            let token = ["NaN", "Infinity", "-Infinity", "1e999", "-1e999", ""][rng.below(6)];
            let mutated = if token.is_empty() {
                text[..i].to_string()
            } else {
                format!("{}{token}{}", &text[..i], &text[i + 1..])
            };
            (
                with_metadata(original, mutated),
                format!("'{token}' at byte {i}"),
            )
        }
        Class::GraphBytesFlipped => {
            let mut bytes = original.write_to_bytes().unwrap();
            let flips = 1 + rng.below(8);
            for _ in 0..flips {
                let i = rng.below(bytes.len());
                bytes[i] ^= 1 << rng.below(8);
            }
            (bytes, format!("{flips} bits flipped"))
        }
        Class::GraphTruncated => {
            let bytes = original.write_to_bytes().unwrap();
            let keep = rng.below(bytes.len());
            (bytes[..keep].to_vec(), format!("cut to {keep} bytes"))
        }
        Class::InterfaceChanged => {
            let mut model = original.clone();
            let graph = model.graph.as_mut().unwrap();
            let what = match rng.below(4) {
                0 => {
                    let i = rng.below(graph.input.len());
                    graph.input[i].name = "renamed".into();
                    format!("input {i} renamed")
                }
                1 => {
                    graph.output[0].name = "y".into();
                    "output renamed".into()
                }
                2 => {
                    let i = rng.below(graph.input.len());
                    let ty = graph.input[i].type_.as_mut().unwrap().mut_tensor_type();
                    ty.elem_type = [1, 6, 7, 10, 11][rng.below(5)];
                    format!("input {i} element type {}", ty.elem_type)
                }
                _ => {
                    let ty = graph.input[0].type_.as_mut().unwrap().mut_tensor_type();
                    let dim = &mut ty.shape.as_mut().unwrap().dim[1];
                    let rows = 1 + rng.below(500) as i64;
                    dim.set_dim_value(rows);
                    format!("x_t declared with {rows} rows")
                }
            };
            (model.write_to_bytes().unwrap(), what)
        }
    }
}

#[derive(Default, Debug)]
struct Tally {
    refused: BTreeMap<&'static str, usize>,
    worked: usize,
}

fn kind(e: &ModelError) -> &'static str {
    match e {
        ModelError::NotOnnx { .. } => "not loadable ONNX",
        ModelError::Metadata(MetadataError::NoMetadata { .. }) => "no metadata",
        ModelError::Metadata(MetadataError::SchemaVersion { .. }) => "schema version",
        ModelError::Metadata(MetadataError::BadMetadata { .. }) => "unreadable metadata",
        ModelError::Metadata(MetadataError::Invalid { .. }) => "metadata breaks a rule",
        ModelError::BadGraph { .. } => "graph interface",
        ModelError::Run { .. } => "failed to run",
        _ => "other",
    }
}

/// Opens, runs and decodes one mutant: `Ok(None)` when it works, `Ok(Some(kind))` when it is
/// refused properly, `Err` when it is refused without saying what is wrong.
fn try_mutant(bytes: &[u8]) -> Result<Option<&'static str>, String> {
    let options = ModelOptions { threads: Some(1) };
    let mut model = match Model::from_bytes(bytes, "mutant.onnx", &options) {
        Ok(m) => m,
        Err(e) => {
            match &e {
                ModelError::Metadata(MetadataError::Invalid { problems, .. }) => {
                    let fields = ["network", "diffusion", "layout", "normalizer", "training"];
                    if let Some(p) = problems
                        .iter()
                        .find(|p| !fields.iter().any(|f| p.starts_with(f)))
                    {
                        return Err(format!("a problem that names no field: {p}"));
                    }
                }
                ModelError::Metadata(MetadataError::BadMetadata { message, .. })
                    if !(message.contains("at field")
                        || message.contains("no 'sinmdm.metadata'")) =>
                {
                    return Err(format!("unreadable metadata without a field: {message}"));
                }
                _ if e.to_string().is_empty() => return Err("an empty error".into()),
                _ => {}
            }
            return Ok(Some(kind(&e)));
        }
    };
    let request = Request {
        task: Task::Generate { frames: 24 },
        count: 1,
        seed: 1,
        steps: Some(2),
        feet: sinmdm::Feet::default(),
        method: Default::default(),
    };
    match sinmdm::run(&mut model, &request, &mut |_, _| ControlFlow::Continue(())) {
        Ok(generated) => match generated.poses(0) {
            Ok(_) => Ok(None),
            Err(_) => Ok(Some("decoding refused")),
        },
        Err(e) if e.to_string().is_empty() => Err("an empty error".into()),
        Err(_) => Ok(Some("run refused")),
    }
}

#[test]
fn mutated_model_files_are_refused_or_work_and_never_crash() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/data/models/walk_tiny.onnx");
    let bytes = std::fs::read(&path).unwrap();
    // The file itself opens and runs.
    assert_eq!(try_mutant(&bytes), Ok(None));
    let original = ModelProto::parse_from_bytes(&bytes).unwrap();
    let json: Value = original
        .metadata_props
        .iter()
        .find(|e| e.key == METADATA_KEY)
        .map(|e| serde_json::from_str(&e.value).unwrap())
        .unwrap();
    let cases: usize = std::env::var("SINMDM_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2_100);
    let mut rng = Rng(20261122);
    let mut tallies: BTreeMap<Class, Tally> = BTreeMap::new();
    let mut failures = Vec::new();
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let started = Instant::now();
    for case in 0..cases {
        let class = CLASSES[case % CLASSES.len()];
        let (bytes, what) = mutant(&original, &json, class, &mut rng);
        let before = Instant::now();
        LARGEST.store(0, Ordering::Relaxed);
        let outcome = std::panic::catch_unwind(AssertUnwindSafe(|| try_mutant(&bytes)));
        let largest = LARGEST.load(Ordering::Relaxed);
        let tally = tallies.entry(class).or_default();
        let case = format!("case {case} {class:?} ({what})");
        match outcome {
            Ok(Ok(None)) => tally.worked += 1,
            Ok(Ok(Some(kind))) => *tally.refused.entry(kind).or_default() += 1,
            Ok(Err(problem)) => failures.push(format!("{case}: {problem}")),
            Err(_) => failures.push(format!("{case}: PANIC")),
        }
        if largest > ALLOCATION_LIMIT {
            failures.push(format!("{case}: allocated {largest} bytes at once"));
        }
        if before.elapsed() > TIME_LIMIT {
            failures.push(format!("{case}: took {:?}", before.elapsed()));
        }
    }
    std::panic::set_hook(default_hook);
    println!(
        "{cases} mutated model files in {:.0} s:",
        started.elapsed().as_secs_f64()
    );
    for (class, tally) in &tallies {
        let refused: usize = tally.refused.values().sum();
        println!(
            "  {class:?}: {refused} refused {:?}, {} worked",
            tally.refused, tally.worked
        );
    }
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

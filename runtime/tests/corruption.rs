//! Thousands of randomly corrupted versions of the shipped clips (bytes flipped, lines cut or
//! duplicated, numbers replaced, files truncated) give an error or a valid clip, never a panic.
//! A valid result is also pushed through the encoder and decoder, which must not panic either.

mod common;

use sinmdm::bvh::{parse_bvh, to_bvh_string};
use sinmdm::diffusion::noise::word;
use sinmdm::motion::{EncodeOptions, decode, encode};

/// A deterministic generator over the runtime's portable noise words (splitmix64), so every
/// failure is reproducible by its case number.
struct Rng {
    seed: u64,
    counter: u64,
}

impl Rng {
    fn next(&mut self) -> u64 {
        self.counter += 1;
        word(self.seed, 0, self.counter)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const REPLACEMENTS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "1e400",
    "-1e309",
    "abc",
    "",
    "0",
    "-0",
    "1e-320",
    "99999999999999999999",
    "{",
    "}",
    "JOINT",
    "End Site",
    "CHANNELS",
    "OFFSET",
    "MOTION",
    "Frames:",
    "ROOT X",
    "1e30",
];

fn corrupt(text: &str, rng: &mut Rng) -> Vec<u8> {
    let mut bytes = text.as_bytes().to_vec();
    for _ in 0..1 + rng.below(3) {
        let lines: Vec<&[u8]> = bytes.split(|&b| b == b'\n').collect();
        let pick = rng.below(lines.len());
        bytes = match rng.below(6) {
            0 => {
                let mut b = bytes.clone();
                let i = rng.below(b.len());
                if !b.is_empty() {
                    b[i] = rng.next() as u8;
                }
                b
            }
            1 => join(
                lines
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| *i != pick)
                    .map(|(_, l)| *l),
            ),
            2 => join(
                lines
                    .iter()
                    .enumerate()
                    .flat_map(|(i, l)| std::iter::repeat_n(*l, if i == pick { 2 } else { 1 })),
            ),
            3 => {
                // Replace one whitespace-separated token of a random line.
                let line = String::from_utf8_lossy(lines[pick]).to_string();
                let mut tokens: Vec<String> = line.split_whitespace().map(String::from).collect();
                if !tokens.is_empty() {
                    let t = rng.below(tokens.len());
                    tokens[t] = REPLACEMENTS[rng.below(REPLACEMENTS.len())].to_string();
                }
                let replaced = tokens.join(" ");
                join(lines.iter().enumerate().map(
                    |(i, l)| {
                        if i == pick { replaced.as_bytes() } else { *l }
                    },
                ))
            }
            4 => bytes[..rng.below(bytes.len() + 1)].to_vec(),
            _ => {
                // Swap two lines.
                let other = rng.below(lines.len());
                let mut order: Vec<&[u8]> = lines.clone();
                order.swap(pick, other);
                join(order.into_iter())
            }
        };
    }
    bytes
}

fn join<'a>(lines: impl Iterator<Item = &'a [u8]>) -> Vec<u8> {
    let mut out = Vec::new();
    for (i, line) in lines.enumerate() {
        if i > 0 {
            out.push(b'\n');
        }
        out.extend_from_slice(line);
    }
    out
}

#[test]
fn corrupted_clips_give_errors_or_valid_clips_never_panics() {
    // The fox is small, so it takes most cases; the larger clips are cut to their first 400
    // lines (the hierarchy and a few hundred frames) to keep the test quick.
    let mut sources = Vec::new();
    for path in common::shipped_clips() {
        let text = std::fs::read_to_string(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let cut: String = text.split_inclusive('\n').take(400).collect();
        // The cut must still be valid before corruption; fix up the frame count.
        let clip = parse_bvh(&text, &name).unwrap();
        let frames_in_cut = cut.lines().count()
            - text
                .lines()
                .position(|l| l.starts_with("Frame Time"))
                .unwrap()
            - 1;
        let cut = cut.replacen(
            &format!("Frames: {}", clip.frame_count()),
            &format!("Frames: {frames_in_cut}"),
            1,
        );
        assert!(parse_bvh(&cut, &name).is_ok(), "{name} cut is invalid");
        sources.push((name, cut));
    }
    let fox = sources.iter().position(|(n, _)| n.contains("fox")).unwrap();
    let mut rng = Rng {
        seed: 0x5EED,
        counter: 0,
    };
    let (mut accepted, mut rejected) = (0, 0);
    let cases = 10_000;
    for case in 0..cases {
        let source = if case % 4 == 0 {
            rng.below(sources.len())
        } else {
            fox
        };
        let (name, text) = &sources[source];
        let bytes = corrupt(text, &mut rng);
        let text = String::from_utf8_lossy(&bytes);
        let outcome = std::panic::catch_unwind(|| match parse_bvh(&text, name) {
            Ok(clip) => {
                let width = clip.skeleton.channel_count();
                assert!(width > 0 && clip.frame_count() > 0);
                assert_eq!(clip.values.len(), width * clip.frame_count());
                assert!(clip.values.iter().all(|v| v.is_finite()));
                assert!(clip.fps.is_finite() && clip.fps > 0.0);
                // Every valid clip goes through the whole representation without a panic.
                if let Ok(encoded) = encode(&clip, &EncodeOptions::default())
                    && let Ok(motion) = decode(&encoded.layout, encoded.features.view())
                {
                    let _ = to_bvh_string(&motion.to_channels());
                }
                true
            }
            Err(e) => {
                assert!(!e.to_string().is_empty());
                false
            }
        });
        match outcome {
            Ok(true) => accepted += 1,
            Ok(false) => rejected += 1,
            Err(_) => panic!("case {case} ({name}) panicked; input:\n{text}"),
        }
    }
    println!("{cases} corrupted clips: {accepted} accepted, {rejected} rejected");
    // Both outcomes occur, or the corruption would not be exercising the reader.
    assert!(
        accepted > cases / 100 && rejected > cases / 4,
        "{accepted} / {rejected}"
    );
}

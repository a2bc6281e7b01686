//! A strict BVH reader: any joint may have 1 to 6 distinct channels in any order (a one-axis
//! hinge, three rotations, positions and rotations), CRLF or LF line ends,
//! End Sites anywhere; every problem is reported with its line, never with a panic.

use std::collections::HashMap;
use std::path::Path;

use super::error::{BvhError, BvhErrorKind};
use super::limits::{BVH_LIMIT, MAX_BVH_JOINTS, MAX_BVH_LINE_WORDS, MAX_BVH_NAME_BYTES};
use crate::files::read_regular_file;
use crate::motion::clip::{ChannelClip, fps_from_frame_time};
use crate::motion::math::Vec3;
use crate::motion::skeleton::{Channel, Joint, Skeleton};

/// Reads a BVH file: a regular file of at most [`MAX_BVH_BYTES`].
pub fn read_bvh(path: impl AsRef<Path>) -> Result<ChannelClip, BvhError> {
    let path = path.as_ref();
    let label = path.display().to_string();
    let bytes = read_regular_file(path, BVH_LIMIT, None).map_err(|e| BvhError {
        file: label.clone(),
        line: None,
        kind: BvhErrorKind::Io(e),
    })?;
    parse_bvh(&String::from_utf8_lossy(&bytes), &label)
}

/// Parses BVH text; `file` names it in error messages.
pub fn parse_bvh(text: &str, file: &str) -> Result<ChannelClip, BvhError> {
    Parser::new(text, file).parse()
}

/// One whitespace-separated token and the 1-based line it is on.
#[derive(Clone, Copy)]
struct Token<'a> {
    line: usize,
    text: &'a str,
}

/// A joint being read: where it started and whether it has seen an OFFSET.
struct OpenJoint {
    index: usize,
    has_offset: bool,
}

struct Parser<'a> {
    file: &'a str,
    lines: Vec<&'a str>,
    /// The hierarchy's tokens read so far: lines are split as the parser reaches them, so a
    /// file refused at its joint limit is never split beyond it.
    tokens: Vec<Token<'a>>,
    next: usize,
    /// Lines of the hierarchy split into `tokens` so far, and where the hierarchy ends.
    split_lines: usize,
    hierarchy_end: usize,
}

impl<'a> Parser<'a> {
    fn new(text: &'a str, file: &'a str) -> Parser<'a> {
        let lines: Vec<&str> = text.split('\n').collect();
        Parser {
            file,
            lines,
            tokens: Vec::new(),
            next: 0,
            split_lines: 0,
            hierarchy_end: 0,
        }
    }

    fn error(&self, line: Option<usize>, kind: BvhErrorKind) -> BvhError {
        BvhError {
            file: self.file.to_string(),
            line,
            kind,
        }
    }

    /// The number of the last line that holds anything.
    fn last_line(&self) -> usize {
        self.lines
            .iter()
            .rposition(|l| !l.trim().is_empty())
            .map_or(1, |i| i + 1)
    }

    fn peek(&mut self) -> Option<Token<'a>> {
        while self.tokens.len() <= self.next && self.split_lines < self.hierarchy_end {
            let i = self.split_lines;
            let line = self.lines[i];
            self.tokens.extend(
                line.split_whitespace()
                    .map(|text| Token { line: i + 1, text }),
            );
            self.split_lines += 1;
        }
        self.tokens.get(self.next).copied()
    }

    fn take(&mut self, expected: &str) -> Result<Token<'a>, BvhError> {
        let token = self.peek().ok_or_else(|| {
            self.error(
                Some(self.last_line()),
                BvhErrorKind::UnexpectedEnd {
                    expected: expected.to_string(),
                },
            )
        })?;
        self.next += 1;
        Ok(token)
    }

    fn expect(&mut self, keyword: &'static str) -> Result<Token<'a>, BvhError> {
        let token = self.take(keyword)?;
        if token.text == keyword {
            Ok(token)
        } else {
            Err(self.error(
                Some(token.line),
                BvhErrorKind::Expected {
                    expected: keyword,
                    found: token.text.to_string(),
                },
            ))
        }
    }

    /// The tokens after `token` on its own line (a joint name may contain spaces).
    fn rest_of_line(&mut self, line: usize) -> Vec<Token<'a>> {
        let mut out = Vec::new();
        while let Some(t) = self.peek() {
            if t.line != line {
                break;
            }
            out.push(t);
            self.next += 1;
        }
        out
    }

    fn number(&mut self, what: &dyn Fn() -> String) -> Result<f64, BvhError> {
        let token = self.take(&what())?;
        parse_number(token.text, what).map_err(|kind| self.error(Some(token.line), kind))
    }

    fn parse(mut self) -> Result<ChannelClip, BvhError> {
        if self.lines.iter().all(|l| l.trim().is_empty()) {
            return Err(self.error(None, BvhErrorKind::Empty));
        }
        // Tokens of the hierarchy: everything up to the line that starts with MOTION.
        let motion_line = self
            .lines
            .iter()
            .position(|l| l.split_whitespace().next() == Some("MOTION"));
        self.hierarchy_end = motion_line.unwrap_or(self.lines.len());
        // A hierarchy line holds a keyword and a few values (or a name of a few words): one of
        // millions of words is refused before it is split.
        for (i, line) in self.lines[..self.hierarchy_end].iter().enumerate() {
            if line.split_whitespace().nth(MAX_BVH_LINE_WORDS).is_some() {
                return Err(self.error(
                    Some(i + 1),
                    BvhErrorKind::OverLimit {
                        what: "a hierarchy line's words".into(),
                        limit: MAX_BVH_LINE_WORDS,
                        name: "MAX_BVH_LINE_WORDS",
                    },
                ));
            }
        }
        let skeleton = self.hierarchy()?;
        if let Some(extra) = self.peek() {
            return Err(self.error(
                Some(extra.line),
                BvhErrorKind::Expected {
                    expected: "MOTION after the root joint's closing '}'",
                    found: extra.text.to_string(),
                },
            ));
        }
        let Some(motion_line) = motion_line else {
            return Err(self.error(
                Some(self.last_line()),
                BvhErrorKind::UnexpectedEnd {
                    expected: "MOTION".to_string(),
                },
            ));
        };
        self.motion(skeleton, motion_line + 1)
    }

    fn hierarchy(&mut self) -> Result<Skeleton, BvhError> {
        self.expect("HIERARCHY")?;
        let root = self.expect("ROOT")?;
        let mut joints: Vec<Joint> = Vec::new();
        let mut first_seen: HashMap<String, usize> = HashMap::new();
        let mut stack: Vec<OpenJoint> = Vec::new();
        self.open_joint(root, None, &mut joints, &mut first_seen, &mut stack)?;
        while let Some(open) = stack.last() {
            let current = open.index;
            let joint_name = joints[current].name.clone();
            let token = self.take(&format!("'}}' closing joint '{joint_name}'"))?;
            match token.text {
                "OFFSET" => {
                    let offset = self.vec3(&|| format!("OFFSET of joint '{joint_name}'"))?;
                    joints[current].offset = offset;
                    if let Some(open) = stack.last_mut() {
                        open.has_offset = true;
                    }
                }
                "CHANNELS" => {
                    let channels = self.channels(&joint_name, token.line)?;
                    joints[current].channels = channels;
                }
                "JOINT" => self.open_joint(
                    token,
                    Some(current),
                    &mut joints,
                    &mut first_seen,
                    &mut stack,
                )?,
                "End" => {
                    self.expect("Site")?;
                    self.expect("{")?;
                    self.expect("OFFSET")?;
                    let end = self.vec3(&|| format!("End Site OFFSET of joint '{joint_name}'"))?;
                    self.expect("}")?;
                    joints[current].end_site = Some(end);
                }
                "}" => {
                    let closed = stack.pop().map(|o| (o.index, o.has_offset));
                    if let Some((index, has_offset)) = closed {
                        let joint = &joints[index];
                        if !has_offset {
                            return Err(self.error(
                                Some(token.line),
                                BvhErrorKind::MissingOffset {
                                    joint: joint.name.clone(),
                                },
                            ));
                        }
                        if joint.channels.is_empty() {
                            return Err(self.error(
                                Some(token.line),
                                BvhErrorKind::NoChannels {
                                    joint: joint.name.clone(),
                                },
                            ));
                        }
                    }
                }
                other => {
                    return Err(self.error(
                        Some(token.line),
                        BvhErrorKind::Expected {
                            expected: "OFFSET, CHANNELS, JOINT, End Site or '}'",
                            found: other.to_string(),
                        },
                    ));
                }
            }
        }
        Ok(Skeleton { joints })
    }

    /// Reads `NAME {` after a ROOT or JOINT keyword and pushes the new joint.
    fn open_joint(
        &mut self,
        keyword: Token<'a>,
        parent: Option<usize>,
        joints: &mut Vec<Joint>,
        first_seen: &mut HashMap<String, usize>,
        stack: &mut Vec<OpenJoint>,
    ) -> Result<(), BvhError> {
        let mut words = self.rest_of_line(keyword.line);
        let brace_on_name_line = words.last().is_some_and(|t| t.text == "{");
        if brace_on_name_line {
            words.pop();
        }
        if words.is_empty() {
            return Err(self.error(
                Some(keyword.line),
                BvhErrorKind::Expected {
                    expected: "a joint name",
                    found: "end of line".to_string(),
                },
            ));
        }
        let name = words.iter().map(|t| t.text).collect::<Vec<_>>().join(" ");
        let over = |what: String, limit: usize, name: &'static str| {
            self.error(
                Some(keyword.line),
                BvhErrorKind::OverLimit { what, limit, name },
            )
        };
        if name.len() > MAX_BVH_NAME_BYTES {
            return Err(over(
                format!("a joint name of {} bytes", name.len()),
                MAX_BVH_NAME_BYTES,
                "MAX_BVH_NAME_BYTES",
            ));
        }
        if joints.len() >= MAX_BVH_JOINTS {
            return Err(over(
                format!("joint '{name}' is joint {}", joints.len() + 1),
                MAX_BVH_JOINTS,
                "MAX_BVH_JOINTS",
            ));
        }

        if let Some(&first_line) = first_seen.get(&name) {
            return Err(self.error(
                Some(keyword.line),
                BvhErrorKind::DuplicateJoint { name, first_line },
            ));
        }
        first_seen.insert(name.clone(), keyword.line);
        if !brace_on_name_line {
            self.expect("{")?;
        }
        joints.push(Joint {
            name,
            parent,
            offset: Vec3::ZERO,
            channels: Vec::new(),
            end_site: None,
        });
        stack.push(OpenJoint {
            index: joints.len() - 1,
            has_offset: false,
        });
        Ok(())
    }

    fn vec3(&mut self, what: &dyn Fn() -> String) -> Result<Vec3, BvhError> {
        Ok(Vec3::new(
            self.number(what)?,
            self.number(what)?,
            self.number(what)?,
        ))
    }

    fn channels(&mut self, joint: &str, line: usize) -> Result<Vec<Channel>, BvhError> {
        let count_token = self.take("the channel count")?;
        let count: usize = count_token.text.parse().map_err(|_| {
            self.error(
                Some(count_token.line),
                BvhErrorKind::BadNumber {
                    what: format!("channel count of joint '{joint}'"),
                    text: count_token.text.to_string(),
                },
            )
        })?;
        if count > 6 {
            return Err(self.error(
                Some(line),
                BvhErrorKind::Expected {
                    expected: "at most 6 channels",
                    found: count.to_string(),
                },
            ));
        }
        let mut channels = Vec::with_capacity(count);
        for _ in 0..count {
            let token = self.take("a channel name")?;
            let channel = Channel::parse(token.text).ok_or_else(|| {
                self.error(
                    Some(token.line),
                    BvhErrorKind::UnknownChannel {
                        joint: joint.to_string(),
                        name: token.text.to_string(),
                    },
                )
            })?;
            if channels.contains(&channel) {
                return Err(self.error(
                    Some(token.line),
                    BvhErrorKind::RepeatedChannel {
                        joint: joint.to_string(),
                        channel: channel.to_string(),
                    },
                ));
            }
            channels.push(channel);
        }
        Ok(channels)
    }

    /// The next non-empty line as a `WORDS: VALUE` header; returns its line number and value.
    fn header<'t>(
        &self,
        lines: &mut impl Iterator<Item = (usize, &'t str)>,
        words: &[&str],
        expected: &'static str,
    ) -> Result<(usize, &'t str), BvhError> {
        let (line, text) = lines.next().ok_or_else(|| {
            self.error(
                Some(self.last_line()),
                BvhErrorKind::UnexpectedEnd {
                    expected: expected.to_string(),
                },
            )
        })?;
        let value = header_value(text, words).ok_or_else(|| {
            self.error(
                Some(line),
                BvhErrorKind::Expected {
                    expected,
                    found: text.to_string(),
                },
            )
        })?;
        Ok((line, value))
    }

    /// The MOTION block: `Frames:`, `Frame Time:` and one line of values per frame.
    fn motion(&self, skeleton: Skeleton, first_line: usize) -> Result<ChannelClip, BvhError> {
        let mut lines = self.lines[first_line..]
            .iter()
            .enumerate()
            .map(|(i, l)| (first_line + i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty());

        let (frames_line, count_text) = self.header(&mut lines, &["Frames"], "'Frames: N'")?;
        let announced: usize = count_text.parse().map_err(|_| {
            self.error(
                Some(frames_line),
                BvhErrorKind::BadNumber {
                    what: "Frames".to_string(),
                    text: count_text.to_string(),
                },
            )
        })?;
        if announced == 0 {
            return Err(self.error(Some(frames_line), BvhErrorKind::ZeroFrames));
        }
        let (time_line, time_text) =
            self.header(&mut lines, &["Frame", "Time"], "'Frame Time: SECONDS'")?;
        let frame_time = match time_text.parse::<f64>() {
            Ok(t) if t.is_finite() && t > 0.0 => t,
            _ => {
                return Err(self.error(
                    Some(time_line),
                    BvhErrorKind::BadFrameTime(time_text.to_string()),
                ));
            }
        };

        let width = skeleton.channel_count();
        let channel_names: Vec<String> = skeleton
            .joints
            .iter()
            .flat_map(|j| j.channels.iter().map(move |c| format!("{} {}", j.name, c)))
            .collect();
        // Reserve no more than the file can hold, whatever `Frames:` claims.
        let remaining = self.lines.len().saturating_sub(time_line);
        let mut values = Vec::with_capacity(announced.min(remaining) * width);
        let mut found = 0usize;
        for (line, text) in lines {
            if found == announced {
                return Err(self.error(Some(line), BvhErrorKind::TooManyFrames { announced }));
            }
            let before = values.len();
            for (c, token) in text.split_whitespace().enumerate() {
                if c >= width {
                    break;
                }
                let value = parse_number(token, || {
                    format!("frame {found}, value {} ({})", c + 1, channel_names[c])
                })
                .map_err(|kind| self.error(Some(line), kind))?;
                values.push(value);
            }
            let count = text.split_whitespace().count();
            if count != width {
                values.truncate(before);
                return Err(self.error(
                    Some(line),
                    BvhErrorKind::WrongValueCount {
                        frame: found,
                        expected: width,
                        found: count,
                    },
                ));
            }
            found += 1;
        }
        if found < announced {
            return Err(self.error(
                Some(self.last_line()),
                BvhErrorKind::Truncated { announced, found },
            ));
        }
        Ok(ChannelClip {
            skeleton,
            fps: fps_from_frame_time(frame_time),
            values,
        })
    }
}

/// The value after a header keyword such as `Frames:` or `Frame Time:` (the colon may stand
/// alone or be attached to the last word or the value).
fn header_value<'t>(line: &'t str, words: &[&str]) -> Option<&'t str> {
    let mut rest = line;
    for (i, word) in words.iter().enumerate() {
        rest = rest.trim_start().strip_prefix(word)?;
        if i + 1 < words.len() && !rest.starts_with(char::is_whitespace) {
            return None;
        }
    }
    let rest = rest.trim_start().strip_prefix(':')?.trim();
    (!rest.is_empty() && !rest.contains(char::is_whitespace)).then_some(rest)
}

/// Parses a finite decimal number; `what` describes the value for the error message.
fn parse_number(text: &str, what: impl FnOnce() -> String) -> Result<f64, BvhErrorKind> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(BvhErrorKind::NonFinite {
            what: what(),
            text: text.to_string(),
        }),
        Err(_) => Err(BvhErrorKind::BadNumber {
            what: what(),
            text: text.to_string(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_values_accept_common_spellings() {
        assert_eq!(header_value("Frames: 12", &["Frames"]), Some("12"));
        assert_eq!(header_value("Frames :12", &["Frames"]), Some("12"));
        assert_eq!(
            header_value("Frame Time:\t.0083333", &["Frame", "Time"]),
            Some(".0083333")
        );
        assert_eq!(header_value("Frames 12", &["Frames"]), None);
        assert_eq!(header_value("FrameTime: 0.1", &["Frame", "Time"]), None);
        assert_eq!(header_value("Frames: 1 2", &["Frames"]), None);
    }
}

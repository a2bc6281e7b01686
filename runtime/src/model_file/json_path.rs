//! The dotted path of the JSON value at a position in a JSON text, so a parse error of the
//! metadata can name its field (`layout.skeleton.joints[3].parent`) and not only a column.

enum Container {
    Object(Option<String>),
    Array(usize),
}

/// The path of the value that the character at `offset` (bytes) of `text` belongs to; empty at
/// the top level. `text` need not be valid JSON past `offset`.
pub(crate) fn path_at(text: &str, offset: usize) -> String {
    let mut stack: Vec<Container> = Vec::new();
    let mut chars = text.char_indices().peekable();
    // Whether the next string inside an object is a key.
    let mut expecting_key = false;
    while let Some((i, c)) = chars.next() {
        if i >= offset {
            break;
        }
        match c {
            '{' => {
                stack.push(Container::Object(None));
                expecting_key = true;
            }
            '[' => stack.push(Container::Array(0)),
            '}' | ']' => {
                stack.pop();
                expecting_key = false;
            }
            ',' => match stack.last_mut() {
                Some(Container::Array(n)) => *n += 1,
                Some(Container::Object(_)) => expecting_key = true,
                None => {}
            },
            ':' => expecting_key = false,
            '"' => {
                let mut s = String::new();
                while let Some((_, c)) = chars.next() {
                    match c {
                        '\\' => {
                            if let Some((_, e)) = chars.next() {
                                s.push(e);
                            }
                        }
                        '"' => break,
                        c => s.push(c),
                    }
                }
                if expecting_key && let Some(Container::Object(key)) = stack.last_mut() {
                    *key = Some(s);
                }
            }
            _ => {}
        }
    }
    let mut path = String::new();
    for container in &stack {
        match container {
            Container::Object(Some(key)) => {
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(key);
            }
            Container::Object(None) => {}
            Container::Array(n) => path.push_str(&format!("[{n}]")),
        }
    }
    path
}

/// The byte offset of a 1-based `line` and `column` (characters) in `text`.
pub(crate) fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let start: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    text[start.min(text.len())..]
        .char_indices()
        .nth(column.saturating_sub(1))
        .map_or(text.len(), |(i, _)| start + i)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_name_object_keys_and_array_indices() {
        let text = r#"{"a": {"b": [1, {"c": "x\"y", "d": 5}]}, "e": 2}"#;
        assert_eq!(path_at(text, text.find('5').unwrap()), "a.b[1].d");
        assert_eq!(path_at(text, text.find('1').unwrap()), "a.b[0]");
        assert_eq!(path_at(text, text.find('2').unwrap()), "e");
        assert_eq!(path_at(text, text.find("x\\").unwrap()), "a.b[1].c");
        assert_eq!(offset_of("ab\ncd", 2, 2), 4);
    }
}

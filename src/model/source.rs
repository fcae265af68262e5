//! Where in a user's text file something went wrong: the line and column, and at most a
//! short excerpt of the text (a line can be 200 KB long; an error quoting it whole buries
//! the message and floods a terminal).

/// Characters of a user's text an error message quotes at most.
pub const EXCERPT_CHARS: usize = 60;

/// 1-based line and column of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// `s` cut to [`EXCERPT_CHARS`] characters, with `...` when cut.
pub fn excerpt(s: &str) -> String {
    match s.char_indices().nth(EXCERPT_CHARS) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

/// A TOML error as `file:line:column: message (near ...)`, the message's first line only
/// and short (the crate's own rendering quotes the whole offending line).
pub fn toml_error(file: &str, text: &str, e: &toml::de::Error) -> String {
    match place(text, e) {
        Some((l, c, near)) => format!("{file}:{l}:{c}: {} (near `{near}`)", message(e)),
        None => format!("{file}: {}", message(e)),
    }
}

/// The same as `line L, column C: message (near ...)`, for a message that names the file
/// already.
pub fn toml_at(text: &str, e: &toml::de::Error) -> String {
    match place(text, e) {
        Some((l, c, near)) => format!("line {l}, column {c}: {} (near `{near}`)", message(e)),
        None => message(e),
    }
}

/// The error's message alone: its first line, at most 400 characters.
pub fn message(e: &toml::de::Error) -> String {
    let msg = e.message().lines().next().unwrap_or("").trim_end();
    match msg.char_indices().nth(400) {
        Some((i, _)) => format!("{} ...", &msg[..i]),
        None => msg.to_string(),
    }
}

/// Line, column and a short excerpt starting a little before the column.
fn place(text: &str, e: &toml::de::Error) -> Option<(usize, usize, String)> {
    let (l, c) = line_col(text, e.span()?.start);
    let line = text.lines().nth(l - 1).unwrap_or("");
    let from = line
        .char_indices()
        .nth(c.saturating_sub(20))
        .map_or(line.len(), |(i, _)| i);
    Some((l, c, excerpt(&line[from..])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_deeply_nested_array_gives_a_short_error_with_its_place() {
        let text = format!(
            "x = 1\na = {}{}\n",
            "[".repeat(100_000),
            "]".repeat(100_000)
        );
        let e = toml::from_str::<toml::Table>(&text).unwrap_err();
        let m = toml_error("deep.toml", &text, &e);
        assert!(m.starts_with("deep.toml:2:"), "{m}");
        assert!(m.len() < 600, "{} bytes: {m}", m.len());
        assert!(m.contains("recursion") || m.contains("depth"), "{m}");
        let at = toml_at(&text, &e);
        assert!(at.starts_with("line 2, column "), "{at}");
    }

    #[test]
    fn columns_count_characters_and_offsets_inside_a_character_are_safe() {
        assert_eq!(line_col("a\n町家 = ", 8), (2, 3));
        assert_eq!(line_col("町", 1), (1, 1));
        assert_eq!(
            excerpt(&"町".repeat(100)).chars().count(),
            EXCERPT_CHARS + 3
        );
    }
}

//! A file's text as people are shown it: characters a terminal would act
//! on or that hide or reorder text are made visible, and long stretches
//! are shortened.

use std::{borrow::Cow, fmt::Write};

/// How many characters of the file a message quotes.
const QUOTED_CHARS: usize = 24;

/// Characters never shown raw: control characters other than the tab
/// (a terminal acts on them), and the invisible ones that hide or reorder
/// text (zero-width marks, bidirectional controls, line and paragraph
/// separators, the byte-order mark).
pub fn is_hidden(c: char) -> bool {
    (c.is_control() && c != '\t')
        || matches!(c, '\u{200B}'..='\u{200F}' | '\u{2028}'..='\u{202E}' | '\u{2060}'..='\u{2069}' | '\u{FEFF}')
}

/// `text` with its hidden characters written as escapes (`\u{1b}`);
/// borrowed when it has none.
pub fn escaped(text: &str) -> Cow<'_, str> {
    if !text.chars().any(is_hidden) {
        return Cow::Borrowed(text);
    }
    let mut shown = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if is_hidden(c) {
            let _ = write!(shown, "\\u{{{:x}}}", u32::from(c));
        } else {
            shown.push(c);
        }
    }
    Cow::Owned(shown)
}

/// `text` as a message quotes it: escaped, and a long one cut short with
/// its length.
pub fn quoted(text: &str) -> String {
    match text.char_indices().nth(QUOTED_CHARS) {
        None => escaped(text).into_owned(),
        Some((cut, _)) => format!("{}… ({} characters)", escaped(&text[..cut]), text.chars().count()),
    }
}

/// One visible character for a hidden one, where columns must stay as
/// they are (source lines under markers): the control pictures of Unicode
/// for C0 controls and DEL, the replacement character for the others.
pub fn picture(c: char) -> char {
    match u32::from(c) {
        code @ 0..=0x1F => char::from_u32(0x2400 + code).unwrap_or(char::REPLACEMENT_CHARACTER),
        0x7F => '\u{2421}',
        _ => char::REPLACEMENT_CHARACTER,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hidden_characters_are_escaped_and_long_text_cut() {
        assert!(matches!(escaped("N10 X1"), Cow::Borrowed(_)));
        assert_eq!(escaped("a\u{0}b\u{1b}[2J\u{202E}\tc"), "a\\u{0}b\\u{1b}[2J\\u{202e}\tc");
        assert_eq!(quoted("XYZ"), "XYZ");
        assert_eq!(quoted(&"X".repeat(1000)), format!("{}… (1000 characters)", "X".repeat(24)));
        assert_eq!(picture('\0'), '␀');
        assert_eq!(picture('\u{1b}'), '␛');
        assert_eq!(picture('\u{7f}'), '␡');
        assert_eq!(picture('\u{FEFF}'), '\u{FFFD}');
    }
}

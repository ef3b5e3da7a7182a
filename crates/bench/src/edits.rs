//! Seeded random edits of generated programs, the way a programmer types.

use std::ops::Range;

use crate::cnc8x6::progen::is_motion_block;
pub use crate::lcg::Lcg;

/// Replace the bytes of `range` with `insert`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Edit {
    pub range: Range<usize>,
    pub insert: String,
}

/// Coordinate words, whose digits are typed and deleted. Other words (G, M,
/// N, F, S) keep theirs, so that the program keeps its meaning and stays
/// roughly valid: a digit more or less in a coordinate moves one point.
const COORDINATES: &[u8] = b"XYZIJK";

/// A single-character edit in a random motion block of a generated program
/// of any dialect: a digit typed into a coordinate (40%), a digit deleted
/// from a coordinate that has more than one (30%), or a space typed between
/// two words (30%). `None` if no block of `text` offers such a place.
pub fn typing_edit(text: &str, rng: &mut Lcg) -> Option<Edit> {
    // Nearly every line of a generated program qualifies; a text with no
    // block line gives up after a bounded number of tries.
    for _ in 0..1000 {
        let mut at = rng.below(text.len().max(1));
        while !text.is_char_boundary(at) {
            at -= 1;
        }
        let start = text[..at].rfind('\n').map_or(0, |i| i + 1);
        let end = text[start..].find('\n').map_or(text.len(), |i| start + i);
        let line = &text[start..end];
        if !is_motion_block(line) {
            continue;
        }
        let kind = rng.below(10);
        let mut places = Vec::new();
        let mut word_start = 0;
        for word in line.split(' ') {
            let coordinate = word.as_bytes().first().is_some_and(|b| COORDINATES.contains(b));
            let digits = word.bytes().filter(u8::is_ascii_digit).count();
            if kind >= 7 {
                if !word.is_empty() && word_start > 0 {
                    places.push(word_start);
                }
            } else if coordinate && (kind < 4 || digits > 1) {
                places.extend(word.char_indices().filter(|(_, c)| c.is_ascii_digit()).map(|(i, _)| word_start + i));
            }
            word_start += word.len() + 1;
        }
        if places.is_empty() {
            continue;
        }
        let place = start + places[rng.below(places.len())];
        return Some(match kind {
            0..4 => Edit { range: place..place, insert: char::from(b'0' + rng.below(10) as u8).to_string() },
            4..7 => Edit { range: place..place + 1, insert: String::new() },
            _ => Edit { range: place..place, insert: " ".into() },
        });
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cnc8x6::progen::{self, Syntax};

    #[test]
    fn edits_touch_only_coordinates_and_spaces_between_words() {
        for syntax in [Syntax::Cnc8x6, Syntax::HaasLathe, Syntax::Sinumerik] {
            edits_touch_only_coordinates_and_spaces(progen::write(&progen::surfacing(2000), syntax));
        }
    }

    fn edits_touch_only_coordinates_and_spaces(mut text: String) {
        let mut rng = Lcg::new(7);
        let (mut typed, mut deleted, mut spaces) = (0, 0, 0);
        for _ in 0..300 {
            let edit = typing_edit(&text, &mut rng).unwrap();
            let line_start = text[..edit.range.start].rfind('\n').unwrap() + 1;
            let line_end = text[line_start..].find('\n').unwrap() + line_start;
            assert!(is_motion_block(&text[line_start..line_end]), "{:?}", &text[line_start..line_end]);
            let before = &text[line_start..edit.range.start];
            assert!(before.contains(' '), "{before:?}");
            match (edit.range.len(), edit.insert.as_str()) {
                (0, " ") => {
                    spaces += 1;
                    assert!(before.ends_with(' '), "{before:?}");
                }
                (0, digit) => {
                    typed += 1;
                    assert!(digit.len() == 1 && digit.as_bytes()[0].is_ascii_digit());
                    assert!(text.as_bytes()[edit.range.start].is_ascii_digit());
                }
                (1, "") => {
                    deleted += 1;
                    assert!(text.as_bytes()[edit.range.start].is_ascii_digit());
                }
                other => panic!("unexpected edit {other:?}"),
            }
            let word_start = before.rfind(' ').unwrap() + 1;
            let letter = text.as_bytes()[line_start + word_start];
            assert!(edit.insert == " " || COORDINATES.contains(&letter), "{}", letter as char);
            text.replace_range(edit.range, &edit.insert);
        }
        assert!(typed > 60 && deleted > 45 && spaces > 45, "{typed} {deleted} {spaces}");
    }

    #[test]
    fn text_without_blocks_gives_no_edit() {
        assert_eq!(typing_edit("%1\n\"COMMENT\"\n*\n", &mut Lcg::new(1)), None);
        assert_eq!(typing_edit("O1 (G1 X1)\nN1 M30\n", &mut Lcg::new(1)), None);
        assert_eq!(typing_edit("", &mut Lcg::new(1)), None);
    }
}

//! The CNC8x6 dialect's part of the benchmarks: the program generator, and
//! where its programs have a code to hover.

pub mod progen;

use crate::edits::Lcg;

/// The offset of a random character of the first G word at or after a
/// random line within ten lines of `offset`.
pub fn g_code_near(text: &str, offset: usize, rng: &mut Lcg) -> Option<usize> {
    let mut start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let (up, down) = match rng.below(21) {
        lines @ 0..10 => (lines + 1, 0),
        lines => (0, lines - 10),
    };
    for _ in 0..up {
        start = text[..start.saturating_sub(1)].rfind('\n').map_or(0, |i| i + 1);
    }
    for _ in 0..down {
        start = text[start..].find('\n').map_or(start, |i| start + i + 1);
    }
    let mut line_start = start;
    for line in text[start..].split_inclusive('\n') {
        if line.starts_with('N') {
            let mut word_start = line_start;
            for word in line.trim_end().split(' ') {
                if word.len() > 1 && word.starts_with('G') && word.as_bytes()[1].is_ascii_digit() {
                    return Some(word_start + rng.below(word.len()));
                }
                word_start += word.len() + 1;
            }
        }
        line_start += line.len();
    }
    None
}

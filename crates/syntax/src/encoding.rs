//! Reading program files into text, and writing text back, without losing a byte.
//!
//! The tree works on `str`. At the file boundary a program is read as UTF-8
//! when it is valid UTF-8, and otherwise as Kamenický (KEYBCS2), the code
//! page the control's manual asks for in comments. Kamenický maps each of the
//! 256 byte values to a different character, so *any* byte sequence decodes
//! and encodes back to exactly the same bytes: files from the control keep
//! their Czech comments, and even binary garbage round-trips.

/// How the bytes of a file were turned into text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Encoding {
    Utf8,
    Kamenicky,
}

/// Decodes a program file. Never fails; UTF-8 input is not copied.
pub fn decode(bytes: Vec<u8>) -> (String, Encoding) {
    match String::from_utf8(bytes) {
        Ok(text) => (text, Encoding::Utf8),
        Err(error) => (error.into_bytes().into_iter().map(kamenicky_char).collect(), Encoding::Kamenicky),
    }
}

/// Encodes text for writing back to a file read with `encoding`. Characters
/// Kamenický cannot represent become `?` (only text an edit introduced can
/// contain them).
pub fn encode(text: &str, encoding: Encoding) -> Vec<u8> {
    match encoding {
        Encoding::Utf8 => text.as_bytes().to_vec(),
        Encoding::Kamenicky => text.chars().map(|c| kamenicky_byte(c).unwrap_or(b'?')).collect(),
    }
}

fn kamenicky_char(byte: u8) -> char {
    match byte {
        0..=0x7F => char::from(byte),
        _ => KAMENICKY_HIGH[usize::from(byte - 0x80)],
    }
}

fn kamenicky_byte(c: char) -> Option<u8> {
    if c.is_ascii() {
        return Some(c as u8);
    }
    KAMENICKY_HIGH.iter().position(|&k| k == c).map(|i| 0x80 + i as u8)
}

/// Bytes 0x80–0xFF: Czech and Slovak letters in 0x80–0xAD, the rest as in
/// code page 437.
const KAMENICKY_HIGH: [char; 128] = [
    'Č', 'ü', 'é', 'ď', 'ä', 'Ď', 'Ť', 'č', 'ě', 'Ě', 'Ĺ', 'Í', 'ľ', 'ĺ', 'Ä', 'Á', //
    'É', 'ž', 'Ž', 'ô', 'ö', 'Ó', 'ů', 'Ú', 'ý', 'Ö', 'Ü', 'Š', 'Ľ', 'Ý', 'Ř', 'ť', //
    'á', 'í', 'ó', 'ú', 'ň', 'Ň', 'Ů', 'Ô', 'š', 'ř', 'ŕ', 'Ŕ', '¼', '§', '«', '»', //
    '░', '▒', '▓', '│', '┤', '╡', '╢', '╖', '╕', '╣', '║', '╗', '╝', '╜', '╛', '┐', //
    '└', '┴', '┬', '├', '─', '┼', '╞', '╟', '╚', '╔', '╩', '╦', '╠', '═', '╬', '╧', //
    '╨', '╤', '╥', '╙', '╘', '╒', '╓', '╫', '╪', '┘', '┌', '█', '▄', '▌', '▐', '▀', //
    'α', 'ß', 'Γ', 'π', 'Σ', 'σ', 'µ', 'τ', 'Φ', 'Θ', 'Ω', 'δ', '∞', 'φ', 'ε', '∩', //
    '≡', '±', '≥', '≤', '⌠', '⌡', '÷', '≈', '°', '∙', '·', '√', 'ⁿ', '²', '■', '\u{A0}', //
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kamenicky_is_one_to_one() {
        let mut seen = std::collections::HashSet::new();
        for byte in 0..=255u8 {
            let c = kamenicky_char(byte);
            assert!(seen.insert(c), "{c:?} appears twice");
            assert_eq!(kamenicky_byte(c), Some(byte));
        }
    }

    #[test]
    fn every_byte_sequence_round_trips() {
        let bytes: Vec<u8> = (0..=255u8).chain([0xFF, 0x80, b'N']).collect();
        let (text, encoding) = decode(bytes.clone());
        assert_eq!(encoding, Encoding::Kamenicky);
        assert_eq!(encode(&text, encoding), bytes);
    }

    #[test]
    fn czech_comment_from_the_control() {
        // "ŘEZÁNÍ" in Kamenický.
        let (text, encoding) = decode(b"N10 \"\x9EEZ\x8FN\x8B\"".to_vec());
        assert_eq!((text.as_str(), encoding), ("N10 \"ŘEZÁNÍ\"", Encoding::Kamenicky));
        let (text, encoding) = decode("N10 \"ŘEZÁNÍ\"".into());
        assert_eq!((text.as_str(), encoding), ("N10 \"ŘEZÁNÍ\"", Encoding::Utf8));
    }
}

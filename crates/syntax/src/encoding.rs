//! Reading program files into text, and writing text back, without losing a byte.
//!
//! The tree works on `str`. At the file boundary a program is read as UTF-8
//! when it is valid UTF-8, and otherwise as Kamenický (KEYBCS2), the code
//! page the control's manual asks for in comments. Kamenický maps each of the
//! 256 byte values to a different character, so *any* byte sequence decodes
//! and encodes back to exactly the same bytes: files from the control keep
//! their Czech comments, and even binary garbage round-trips.
//!
//! A file that starts with the byte-order mark of UTF-16 or UTF-32 (an
//! editor's "Unicode" text) is read in that encoding when all of it decodes,
//! the mark kept as the text's first character (U+FEFF), so that the
//! parser reports the encoding once and checks the program as written.

/// How the bytes of a file were turned into text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Encoding {
    Utf8,
    Kamenicky,
    Utf16 { big_endian: bool },
    Utf32 { big_endian: bool },
}

/// The byte-order mark, as the text's first character.
pub const BYTE_ORDER_MARK: char = '\u{FEFF}';

/// Decodes a program file. Never fails; UTF-8 input is not copied.
pub fn decode(bytes: Vec<u8>) -> (String, Encoding) {
    if let Some(decoded) = decode_wide(&bytes) {
        return decoded;
    }
    match String::from_utf8(bytes) {
        Ok(text) => (text, Encoding::Utf8),
        Err(error) => (error.into_bytes().into_iter().map(kamenicky_char).collect(), Encoding::Kamenicky),
    }
}

/// UTF-32 or UTF-16 text behind its byte-order mark; `None` without a mark
/// or when any unit does not decode. UTF-32 is tried first: its
/// little-endian mark starts like UTF-16's.
fn decode_wide(bytes: &[u8]) -> Option<(String, Encoding)> {
    let utf32 = |big_endian: bool| -> Option<(String, Encoding)> {
        let units = bytes.chunks(4).map(|unit| {
            let unit: [u8; 4] = unit.try_into().ok()?;
            char::from_u32(if big_endian { u32::from_be_bytes(unit) } else { u32::from_le_bytes(unit) })
        });
        Some((units.collect::<Option<String>>()?, Encoding::Utf32 { big_endian }))
    };
    let utf16 = |big_endian: bool| -> Option<(String, Encoding)> {
        if !bytes.len().is_multiple_of(2) {
            return None;
        }
        let units = bytes.chunks_exact(2).map(|unit| {
            let unit = [unit[0], unit[1]];
            if big_endian { u16::from_be_bytes(unit) } else { u16::from_le_bytes(unit) }
        });
        Some((char::decode_utf16(units).collect::<Result<String, _>>().ok()?, Encoding::Utf16 { big_endian }))
    };
    match bytes {
        [0xFF, 0xFE, 0, 0, ..] => utf32(false).or_else(|| utf16(false)),
        [0, 0, 0xFE, 0xFF, ..] => utf32(true),
        [0xFF, 0xFE, ..] => utf16(false),
        [0xFE, 0xFF, ..] => utf16(true),
        _ => None,
    }
}

/// Encodes text for writing back to a file read with `encoding`. Characters
/// Kamenický cannot represent become `?` (only text an edit introduced can
/// contain them).
pub fn encode(text: &str, encoding: Encoding) -> Vec<u8> {
    match encoding {
        Encoding::Utf8 => text.as_bytes().to_vec(),
        Encoding::Kamenicky => text.chars().map(|c| kamenicky_byte(c).unwrap_or(b'?')).collect(),
        Encoding::Utf16 { big_endian } => text
            .encode_utf16()
            .flat_map(|unit| if big_endian { unit.to_be_bytes() } else { unit.to_le_bytes() })
            .collect(),
        Encoding::Utf32 { big_endian } => text
            .chars()
            .flat_map(|c| if big_endian { u32::from(c).to_be_bytes() } else { u32::from(c).to_le_bytes() })
            .collect(),
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
    fn unicode_text_with_a_byte_order_mark_is_decoded() {
        let text = "\u{FEFF}%1\r\nN10 X1 \"ŘEZ 🙂\"\r\n";
        for encoding in [false, true]
            .into_iter()
            .flat_map(|big_endian| [Encoding::Utf16 { big_endian }, Encoding::Utf32 { big_endian }])
        {
            let bytes = encode(text, encoding);
            assert_eq!(decode(bytes.clone()), (text.to_owned(), encoding));
            assert_eq!(encode(text, encoding), bytes);
        }
        // An odd length or a lone surrogate is not UTF-16: read byte by byte.
        assert_eq!(decode(vec![0xFF, 0xFE, b'N']).1, Encoding::Kamenicky);
        assert_eq!(decode(vec![0xFF, 0xFE, 0x00, 0xD8, b'N', 0]).1, Encoding::Kamenicky);
        // A UTF-16 mark followed by U+0000 reads as UTF-32 when it is; the
        // bytes come back either way.
        let odd = vec![0xFF, 0xFE, 0, 0, b'N', 0];
        let (text, encoding) = decode(odd.clone());
        assert_eq!((text.as_str(), encoding), ("\u{FEFF}\0N", Encoding::Utf16 { big_endian: false }));
        assert_eq!(encode(&text, encoding), odd);
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

//! Property tests: any input round-trips byte for byte without a panic, and
//! incremental reparsing always equals a full parse.

use ncc_syntax::{Dialect, Parse, TextEdit, TextRange, TextSize};
use proptest::prelude::*;

/// Text made mostly of the language's own characters, so that the parser's
/// interesting paths are hit, with some foreign ones mixed in.
fn program_text() -> impl Strategy<Value = String> {
    let piece = prop_oneof![
        8 => Just("N".to_owned()),
        8 => "[0-9]{1,4}",
        6 => "[XYZGMFRSTIJ]",
        4 => Just(" ".to_owned()),
        4 => Just("\n".to_owned()),
        2 => Just(".".to_owned()),
        2 => Just("-".to_owned()),
        2 => Just("=".to_owned()),
        2 => Just("\"".to_owned()),
        1 => Just("\r\n".to_owned()),
        1 => Just("\r".to_owned()),
        1 => Just("%".to_owned()),
        1 => Just("*".to_owned()),
        1 => Just("/".to_owned()),
        1 => Just("&".to_owned()),
        1 => Just("+".to_owned()),
        1 => "[\u{201C}\u{201D}\u{201E}\u{2212}\u{2013}ČŘáx#,;()\t]",
        1 => any::<char>().prop_map(String::from),
    ];
    prop::collection::vec(piece, 0..120).prop_map(|pieces| pieces.concat())
}

/// A header and well-formed blocks, so that edits mostly take the
/// incremental path rather than the full-parse fallback.
fn block_program() -> impl Strategy<Value = String> {
    let word = prop_oneof![
        "[XYZIJ]-?[0-9]{1,3}(\\.[0-9]{0,3})?",
        "[GM][0-9]{1,2}",
        "R[0-9]{1,2}= ?-?[0-9]{1,4}\\.?",
        "[FST]R[0-9]{1,2}",
        Just("/".to_owned()),
        " ?\"[A-Z N]{0,8}\"?".prop_map(|c| c.replace('\n', "")),
    ];
    let block =
        (1u32..9999, prop::collection::vec(word, 0..5), prop_oneof![Just("\n"), Just("\r\n"), Just("\n "), Just(" ")])
            .prop_map(|(n, words, end)| format!("N{n} {}{end}", words.join(" ")));
    (prop::collection::vec(block, 1..12), prop::bool::ANY)
        .prop_map(|(blocks, star)| format!("%1 \"T\"\n{}{}", blocks.concat(), if star { "*\n" } else { "" }))
}

fn char_boundary(text: &str, at: usize) -> usize {
    (0..=at.min(text.len())).rev().find(|&i| text.is_char_boundary(i)).unwrap()
}

fn assert_well_formed(text: &str, parse: &Parse) {
    assert_eq!(parse.syntax_node().to_string(), text);
    for error in parse.errors() {
        let range = std::ops::Range::<usize>::from(error.range);
        assert!(range.end <= text.len() && text.is_char_boundary(range.start) && text.is_char_boundary(range.end));
        assert!(!error.message.is_empty());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn any_string_round_trips(text in any::<String>()) {
        assert_well_formed(&text, &Parse::new(&text, Dialect::Cnc8x6));
    }

    #[test]
    fn program_like_text_round_trips(text in program_text()) {
        assert_well_formed(&text, &Parse::new(&text, Dialect::Cnc8x6));
    }

    #[test]
    fn reparse_equals_full_parse(
        text in prop_oneof![program_text(), block_program()],
        start in 0usize..2000,
        len in 0usize..12,
        insert in program_text().prop_map(|t| t.chars().take(6).collect::<String>()),
    ) {
        let start = char_boundary(&text, start % (text.len() + 1));
        let end = char_boundary(&text, start + len);
        let edit = TextEdit::replace(
            TextRange::new(TextSize::from(start as u32), TextSize::from(end as u32)),
            insert,
        );
        let old = Parse::new(&text, Dialect::Cnc8x6);
        let mut new_text = text.clone();
        edit.apply(&mut new_text);
        let incremental = old.reparse(&edit, &new_text);
        prop_assert_eq!(incremental, Parse::new(&new_text, Dialect::Cnc8x6));
    }
}

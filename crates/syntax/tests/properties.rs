//! Property tests: any input round-trips byte for byte without a panic, and
//! incremental reparsing always equals a full parse.

mod strategies;

use ncc_syntax::{Dialect, Parse, TextEdit, TextRange, TextSize};
use proptest::prelude::*;
use strategies::{block_program, program_text};

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

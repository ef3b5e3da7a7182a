//! Property tests: any input round-trips byte for byte without a panic, and
//! incremental reparsing always equals a full parse, in every dialect; the
//! tests of CNC8x6's block structure use its grammar.

mod strategies;

use ncc_syntax::{
    BlockParser, Dialect, Parse, TextEdit, TextRange, TextSize,
    ast::AstNode,
    encoding::{self, Encoding},
};
use proptest::prelude::*;
use strategies::{block_program, crowded_lines, overlong_lines, program_text};

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
        for dialect in Dialect::ALL.into_iter() {
            assert_well_formed(&text, &Parse::new(&text, dialect));
        }
    }

    /// The file boundary is lossless, byte-order marks or not.
    #[test]
    fn any_bytes_round_trip(
        mark in prop_oneof![
            Just(vec![]), Just(vec![0xFF, 0xFE]), Just(vec![0xFE, 0xFF]), Just(vec![0xFF, 0xFE, 0, 0]), Just(vec![0, 0, 0xFE, 0xFF]),
        ],
        rest in any::<Vec<u8>>(),
    ) {
        let bytes = [mark, rest].concat();
        let (text, encoding) = encoding::decode(bytes.clone());
        prop_assert_eq!(encoding::encode(&text, encoding), bytes);
    }

    /// Text saved as UTF-16 or UTF-32 with its mark reads back as itself
    /// (unless it is UTF-16 that also reads as UTF-32: it starts with
    /// U+0000).
    #[test]
    fn unicode_files_read_as_their_text(text in any::<String>(), big_endian in any::<bool>(), wide in any::<bool>()) {
        let text = format!("{}{text}", encoding::BYTE_ORDER_MARK);
        let written = if wide { Encoding::Utf32 { big_endian } } else { Encoding::Utf16 { big_endian } };
        let bytes = encoding::encode(&text, written);
        let (read, encoding) = encoding::decode(bytes.clone());
        prop_assert_eq!(encoding::encode(&read, encoding), bytes);
        if !text[3..].starts_with('\0') {
            prop_assert_eq!((read, encoding), (text, written));
        }
    }

    #[test]
    fn program_like_text_round_trips(text in prop_oneof![program_text(), crowded_lines(), overlong_lines()]) {
        for dialect in Dialect::ALL.into_iter() {
            assert_well_formed(&text, &Parse::new(&text, dialect));
        }
    }

    #[test]
    fn blocks_parsed_one_by_one_are_the_tree_blocks(text in prop_oneof![program_text(), block_program(), overlong_lines()]) {
        let parse = Parse::new(&text, Dialect::Cnc8x6);
        let tree = parse.tree();
        let expected: Vec<_> =
            tree.blocks().map(|block| (block.syntax().text_range(), block.syntax().green().to_owned())).collect();
        let mut parser = BlockParser::new(&text);
        let mut at = parser.body().start;
        let mut blocks = Vec::new();
        while let Some((range, green)) = parser.block_at(at) {
            at = range.end().into();
            blocks.push((range, green));
        }
        prop_assert_eq!(blocks, expected);
        let header_text = |header: Option<ncc_syntax::ast::Header>| header.map(|header| header.syntax().to_string());
        prop_assert_eq!(header_text(parser.header()), header_text(tree.header()));
    }

    #[test]
    fn reparse_equals_full_parse(
        text in prop_oneof![program_text(), block_program(), crowded_lines(), overlong_lines()],
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
        let mut new_text = text.clone();
        edit.apply(&mut new_text);
        for dialect in Dialect::ALL.into_iter() {
            let incremental = Parse::new(&text, dialect).reparse(&edit, &new_text);
            prop_assert_eq!(incremental, Parse::new(&new_text, dialect));
        }
    }
}

/// A program of `blocks` numbered blocks with varied words, and every
/// seventh line an unnumbered continuation, long enough for many runs.
fn long_program(blocks: usize) -> String {
    let mut text = String::from("%1\n");
    for i in 0..blocks {
        text.push_str(&format!("N{i} G1 X{}.{} Y{}\n", i * 7 % 1000, i % 10, i * 13 % 997));
        if i % 7 == 0 {
            text.push_str("Z-1.5\n");
        }
    }
    text.push_str("M30\n*\n");
    text
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Edits in programs of many runs: regrouping after each edit must give
    /// the runs of a full parse, however far the change moves run ends.
    #[test]
    fn reparse_of_long_programs_equals_full_parse(
        blocks in 100usize..4000,
        edits in prop::collection::vec(
            (any::<bool>(), any::<prop::sample::Index>(), 0usize..40, "[0-9 NXG\n]{0,4}"),
            1..10,
        ),
    ) {
        let mut text = long_program(blocks);
        let mut parse = Parse::new(&text, Dialect::Cnc8x6);
        for (near_run_end, at, len, insert) in edits {
            // Editing the last block of a run moves where the run ends.
            let run_ends: Vec<usize> = parse.syntax_node().children().map(|run| usize::from(run.text_range().end())).collect();
            let at = if near_run_end { run_ends[at.index(run_ends.len())].saturating_sub(len + 3) } else { at.index(text.len() + 1) };
            let start = char_boundary(&text, at);
            let end = char_boundary(&text, start + len);
            let edit = TextEdit::replace(TextRange::new(TextSize::from(start as u32), TextSize::from(end as u32)), insert);
            edit.apply(&mut text);
            parse = parse.reparse(&edit, &text);
            prop_assert_eq!(&parse, &Parse::new(&text, Dialect::Cnc8x6));
        }
    }
}

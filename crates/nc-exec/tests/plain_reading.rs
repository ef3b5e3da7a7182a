//! The executor reads plain blocks straight from their text; every block
//! must read exactly as its syntax tree lowers.

#[path = "../../syntax/tests/strategies/mod.rs"]
mod strategies;

use nc_exec::cnc8x6::lower::{BlockData, BlockReader};
use ncc_syntax::{Dialect, Parse, TextRange, ast::AstNode};
use proptest::prelude::*;
use strategies::{block_program, crowded_lines, overlong_lines, program_text};

/// Each block's range, lowering, and whether it was read from its text.
fn read(text: &str) -> Vec<(TextRange, BlockData, bool)> {
    let (mut reader, mut data) = (BlockReader::new(text), BlockData::default());
    let mut blocks = Vec::new();
    while let Some((range, tree)) = reader.next_into(&mut data) {
        blocks.push((range, data.clone(), tree.is_none()));
    }
    blocks
}

fn from_tree(text: &str) -> Vec<(TextRange, BlockData)> {
    let parse = Parse::new(text, Dialect::Cnc8x6);
    parse.tree().blocks().map(|block| (block.syntax().text_range(), BlockData::lower(block.syntax().green()))).collect()
}

/// Text made of what plain blocks are made of, and of the near misses that
/// must fall back to the tree.
fn near_plain_text() -> impl Strategy<Value = String> {
    let piece = prop_oneof![
        6 => Just("N".to_owned()),
        8 => "[0-9]{1,3}",
        8 => "[XYZGFR]",
        3 => Just(" ".to_owned()),
        3 => Just("\n".to_owned()),
        2 => Just(".".to_owned()),
        2 => Just("-".to_owned()),
        1 => Just("+".to_owned()),
        2 => Just("=".to_owned()),
        1 => Just("\"".to_owned()),
        1 => Just("\r\n".to_owned()),
        1 => "[ \t]{2}",
        1 => "[/&x*%]",
    ];
    prop::collection::vec(piece, 0..80).prop_map(|pieces| format!("%1\n{}", pieces.concat()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn blocks_read_as_their_tree_lowers(text in prop_oneof![near_plain_text(), block_program(), program_text(), crowded_lines(), overlong_lines()]) {
        let read: Vec<_> = read(&text).into_iter().map(|(range, data, _)| (range, data)).collect();
        prop_assert_eq!(read, from_tree(&text));
    }
}

#[test]
fn cam_output_is_read_without_trees() {
    let text = "%1 \"PART\"\nN1 G54 G90 G00 X0 Y0 Z5. M03 S8000\nN2 G01 X-1.5 Y.25 Z-R12 F2400 \"CUT\"\r\n\
                N3 X+2 R12=-0.5 R13=R12\n   Y3\nN4 M30\n";
    let blocks = read(text);
    assert_eq!(blocks.len(), 4);
    assert!(blocks.iter().all(|&(_, _, plain)| plain));
    assert_eq!(blocks.iter().map(|(range, data, _)| (*range, data.clone())).collect::<Vec<_>>(), from_tree(text));
}

#[test]
fn other_blocks_fall_back_to_their_tree() {
    // Block skip, a space inside a word, a lower-case address, `&`, a split number, a word
    // without its value and words before the first block number.
    for block in ["N1 / X1\n", "N1 X 1\n", "N1 x1\n", "N1 &2\n", "N1 X1 2\n", "N1 X\n", "N1 XR1=2\n"] {
        let text = format!("%1\n{block}N2 M30\n");
        let plain: Vec<bool> = read(&text).into_iter().map(|(_, _, plain)| plain).collect();
        assert_eq!(plain, [false, true], "{block:?}");
    }
    let plain: Vec<bool> = read("%1\nG1 X1\nN2 M30\n").into_iter().map(|(_, _, plain)| plain).collect();
    assert_eq!(plain, [false, true]);
}

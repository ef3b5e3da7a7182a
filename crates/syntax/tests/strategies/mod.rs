//! Generators of program text for property tests, shared with the
//! analysis crate's tests.

use proptest::prelude::*;

/// Text made mostly of the language's own characters, so that the parser's
/// interesting paths are hit, with some foreign ones mixed in.
pub fn program_text() -> impl Strategy<Value = String> {
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
pub fn block_program() -> impl Strategy<Value = String> {
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

/// Blocks on lines crowded with errors of a few kinds, more than a line
/// keeps, sometimes many blocks to a line, so that edits meet lines whose
/// errors were counted rather than kept.
pub fn crowded_lines() -> impl Strategy<Value = String> {
    let item = prop_oneof![Just("X "), Just("1 "), Just("="), Just("x1 "), Just("N1 X "), Just("G1 ")];
    let line = (prop::collection::vec(item, 0..40), prop_oneof![Just("\n"), Just("\r\n"), Just("\r")])
        .prop_map(|(items, end)| format!("N5 {}{end}", items.concat()));
    prop::collection::vec(line, 1..6).prop_map(|lines| format!("%1\n{}", lines.concat()))
}

/// Lines around the length past which ncc leaves a line unread (1024
/// bytes), with block numbers, comments and two-byte characters where
/// reading stops, so that edits meet text read and unread.
pub fn overlong_lines() -> impl Strategy<Value = String> {
    let item = prop_oneof![Just("N1 "), Just("X1.5 "), Just("\"note "), Just("Ř"), Just("G1"), Just(" "), Just("*")];
    let line = (prop::collection::vec(item, 150..400), prop_oneof![Just("\n"), Just("\r\n"), Just("\r")])
        .prop_map(|(items, end)| format!("{}{end}", items.concat()));
    prop::collection::vec(line, 1..4).prop_map(|lines| format!("%1\n{}", lines.concat()))
}

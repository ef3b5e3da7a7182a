//! Any bytes: decoding, parsing and encoding never panic and lose nothing.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ncc_syntax::{Dialect, Parse, encoding};

fuzz_target!(|data: &[u8]| {
    let (text, encoding) = encoding::decode(data.to_vec());
    assert_eq!(encoding::encode(&text, encoding), data);
    let parse = Parse::new(&text, Dialect::Cnc8x6);
    assert_eq!(parse.syntax_node().to_string(), text);
    for error in parse.errors() {
        assert!(usize::from(error.range.end()) <= text.len());
    }
    // The typed layer reads every part of the tree without panicking.
    let file = parse.tree();
    for block in file.blocks() {
        let _ = block.number();
        for word in block.words() {
            let _ = (word.letter(), word.value(), word.value_range());
        }
        for assign in block.assignments() {
            let _ = (assign.index(), assign.value());
        }
        for comment in block.comments() {
            let _ = (comment.is_closed(), comment.body());
        }
    }
});

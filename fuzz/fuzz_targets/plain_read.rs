//! Any text: the executor's reading of blocks (plain ones straight from the
//! text, the others parsed alone) gives the blocks of the whole tree,
//! lowered alike.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nc_exec::cnc8x6::lower::{BlockData, BlockReader};
use ncc_syntax::{Dialect, Parse, ast::AstNode};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let parse = Parse::new(text, Dialect::Cnc8x6);
    let mut reader = BlockReader::new(text);
    let mut lowered = BlockData::default();
    for block in parse.tree().blocks() {
        let (range, _) = reader.next_into(&mut lowered).expect("as many blocks as the tree");
        assert_eq!(range, block.syntax().text_range());
        assert_eq!(lowered, BlockData::lower(block.syntax().green()));
    }
    assert!(reader.next_into(&mut lowered).is_none());
});

//! Any text and any edit: the incremental reparse equals a full parse.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ncc_syntax::{Dialect, Parse, TextEdit, TextRange, TextSize};

fuzz_target!(|input: (String, u16, u8, String)| {
    let (text, start, len, insert) = input;
    let floor = |at: usize| (0..=at.min(text.len())).rev().find(|&i| text.is_char_boundary(i)).unwrap();
    let start = floor(usize::from(start) % (text.len() + 1));
    let end = floor(start + usize::from(len % 16));
    let edit = TextEdit::replace(TextRange::new(TextSize::from(start as u32), TextSize::from(end as u32)), insert);
    let old = Parse::new(&text, Dialect::Cnc8x6);
    let mut new_text = text.clone();
    edit.apply(&mut new_text);
    assert_eq!(old.reparse(&edit, &new_text), Parse::new(&new_text, Dialect::Cnc8x6));
});

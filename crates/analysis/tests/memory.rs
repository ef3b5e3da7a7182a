//! What the analysis keeps of a file, counted in bytes on the heap: a
//! document that closes (its text on disk takes its place) or leaves the
//! workspace leaves nothing computed from it behind.
//!
//! The heap is counted for the whole process, so this binary has one test:
//! no other test allocates meanwhile.
#![allow(unsafe_code)] // The counting allocator below; nothing else.

use std::{
    alloc::{GlobalAlloc, Layout, System},
    sync::atomic::{AtomicIsize, Ordering::Relaxed},
};

use ncc_analysis::{AnalysisHost, FileId, TextEdit, TextRange, TextSize};

/// The system allocator, counting the bytes in use.
struct Counting;

static IN_USE: AtomicIsize = AtomicIsize::new(0);

// SAFETY: every call is forwarded unchanged to the system allocator; the
// counter is only a statistic.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        IN_USE.fetch_add(layout.size() as isize, Relaxed);
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        IN_USE.fetch_sub(layout.size() as isize, Relaxed);
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        IN_USE.fetch_add(new_size as isize - layout.size() as isize, Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// A program whose walk carries parameters and feeds through a subprogram
/// it calls, with a finding every few hundred blocks.
fn program(blocks: usize) -> String {
    let mut text = String::from("%3 \"MEMORY\"\nN1 G90 G17 F100 S500 R1=10.\n");
    for n in 2..=blocks {
        let extra = match n % 97 {
            0 => " G71 L5".to_owned(),
            13 => format!(" F{}", 100 + n),
            29 => " R2=R1 G28 R3=R2".to_owned(),
            _ => String::new(),
        };
        let finding = if n % 400 == 0 { " G02" } else { "" };
        text.push_str(&format!("N{n} G01{finding} X{n}. Y-{n}.{extra}\n"));
    }
    text.push_str("N9000 M30\nN9001 G79 L5\nN9002 G91 X1. F50\nN9003 G70\n*\n");
    text
}

/// Everything an editor asks about a file, so that every result the
/// analysis keeps is there.
fn ask_everything(host: &AnalysisHost, file: FileId, at: usize) {
    let analysis = host.analysis();
    let offset = TextSize::from(at as u32);
    analysis.diagnostics(file);
    analysis.prepare_states(file);
    analysis.hover(file, offset);
    analysis.goto_definition(file, offset);
    analysis.references(file, offset, true);
    analysis.completions(file, offset);
    analysis.document_symbols(file);
    analysis.folding_ranges(file);
    analysis.highlight(file);
    analysis.inlay_hints(file, None);
    analysis.run_input(file);
    analysis.program_head(file);
}

/// Edits spread over the file, each followed by every question.
fn edit_session(host: &mut AnalysisHost, file: FileId, blocks: usize) {
    let mut text = host.analysis().text(file).to_string();
    ask_everything(host, file, text.len() / 2);
    for n in (50..blocks).step_by(300) {
        let at = text.find(&format!("N{n} G01 X")).unwrap() + format!("N{n} G01 X").len();
        let edit = TextEdit::replace(TextRange::empty(TextSize::from(at as u32)), "7");
        host.apply_edit(file, &edit);
        edit.apply(&mut text);
        ask_everything(host, file, at);
    }
}

fn in_use() -> isize {
    IN_USE.load(Relaxed)
}

#[test]
fn a_closed_or_removed_file_leaves_nothing_computed_from_it() {
    let mut host = AnalysisHost::default();
    // What every analysis builds once (the catalogue, salsa's tables)
    // comes first.
    let small = host.add_file("small.NCP", program(300));
    edit_session(&mut host, small, 300);

    let blocks = 3000;
    let disk = program(blocks);
    let before = in_use();
    let file = host.add_file("main.NCP", disk.as_str());
    let loaded = in_use() - before;
    edit_session(&mut host, file, blocks);
    let used = in_use() - before;
    assert!(used > loaded + loaded / 2, "the session kept {used} bytes, the text and its tree {loaded}");

    // The document closes: the text on disk takes its place.
    host.set_text(file, disk.as_str());
    let closed = in_use() - before;
    assert!(closed <= loaded + loaded / 50, "{closed} bytes kept after closing, {loaded} for the text and its tree");

    host.remove_file(file);
    let removed = in_use() - before;
    assert!(removed <= loaded / 50, "{removed} bytes kept after removing, {loaded} for the text and its tree");
}

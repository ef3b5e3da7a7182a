//! Snapshot tests: every program in `test_data/parser` is parsed in the
//! dialect its file name gives (`*.ncp`: CNC8x6) and its tree and errors
//! compared with the `.rast` file next to it.
//! Run with `UPDATE_EXPECT=1` to accept new output.

use std::{fs, path::PathBuf};

use ncc_syntax::{Dialect, Parse, TextEdit, TextRange, TextSize};

fn dialect_of(path: &std::path::Path) -> Option<Dialect> {
    Dialect::by_default_for(path)
}

/// The fixtures with their text and dialect.
fn fixtures() -> Vec<(PathBuf, String, Dialect)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("test_data/parser");
    let mut files: Vec<_> = fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|ext| ext != "rast"))
        .collect();
    files.sort();
    assert!(files.len() >= 20, "fixtures missing in {}", dir.display());
    files
        .into_iter()
        .map(|path| {
            let text = fs::read_to_string(&path).unwrap();
            let dialect = dialect_of(&path).unwrap_or_else(|| panic!("{}: no dialect reads it", path.display()));
            (path, text, dialect)
        })
        .collect()
}

#[test]
fn parser_snapshots() {
    for (path, text, dialect) in fixtures() {
        let parse = Parse::new(&text, dialect);
        assert_eq!(parse.syntax_node().to_string(), text, "{} does not round-trip", path.display());
        let is_error_fixture = path.file_name().unwrap().to_str().unwrap().starts_with("error_");
        let has_errors = parse.errors().iter().any(|e| e.severity() == ncc_syntax::Severity::Error);
        assert_eq!(has_errors, is_error_fixture, "{}: error fixtures are named error_*", path.display());
        expect_test::expect_file![path.with_extension("rast")].assert_eq(&parse.debug_dump());
    }
}

/// Every syntax diagnostic is shown by at least one fixture.
#[test]
fn fixtures_cover_every_syntax_error() {
    let mut seen = std::collections::BTreeSet::new();
    for (_, text, dialect) in fixtures() {
        seen.extend(Parse::new(&text, dialect).errors().iter().map(|e| e.kind));
    }
    // The Haas lathe and Sinumerik grammars have their own fixtures.
    for (dir, extension, dialect) in [
        ("test_data/haas-lathe", "nc", Dialect::HaasLathe),
        ("test_data/sinumerik/constructs", "mpf", Dialect::Sinumerik),
    ] {
        for entry in fs::read_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|ext| ext == extension) {
                let text = fs::read_to_string(&path).unwrap();
                seen.extend(Parse::new(&text, dialect).errors().iter().map(|e| e.kind));
            }
        }
    }
    let missing: Vec<_> = ncc_syntax::SyntaxErrorKind::ALL.iter().filter(|k| !seen.contains(k)).collect();
    assert!(missing.is_empty(), "no fixture shows {missing:?}");
}

/// Deleting each character, and inserting a few interesting ones at each
/// position, reparses to the same result as a full parse.
#[test]
fn fixture_edits_reparse_like_full_parses() {
    for (path, text, dialect) in fixtures() {
        let parse = Parse::new(&text, dialect);
        let boundaries: Vec<usize> = (0..=text.len()).filter(|&i| text.is_char_boundary(i)).collect();
        let mut edits = Vec::new();
        for pair in boundaries.windows(2) {
            edits.push(TextEdit::replace(range(pair[0], pair[1]), ""));
        }
        for &at in &boundaries {
            for insert in ["N", "N5 ", "\"", "\n", " ", "X", "5", "R1=", "*", "%"] {
                edits.push(TextEdit::replace(range(at, at), insert));
            }
        }
        for edit in edits {
            let mut new_text = text.clone();
            edit.apply(&mut new_text);
            let incremental = parse.reparse(&edit, &new_text);
            let full = Parse::new(&new_text, dialect);
            assert_eq!(incremental, full, "{}: {edit:?}", path.display());
        }
    }
}

fn range(start: usize, end: usize) -> TextRange {
    TextRange::new(TextSize::from(start as u32), TextSize::from(end as u32))
}

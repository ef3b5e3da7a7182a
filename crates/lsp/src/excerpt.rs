//! Files as human reports show them: hidden characters drawn as visible
//! ones, and a line too long to read cut to windows around the places
//! reports mark on it.
//!
//! ariadne renders a marked line whole, so a 50 MB line would be written
//! for every finding on it; and it starts a new line at characters the
//! rest of ncc does not (form feed, NEL). It is given each file as shown
//! here instead: the same lines, hidden characters replaced one for one,
//! long lines cut. The column in the place it prints above each snippet
//! is then the shown line's, so [`Shown::restore_places`] writes the file's
//! name and column there.

use std::{collections::HashMap, fmt, ops::Range};

use ariadne::{Cache, Source};
use ncc_analysis::{TextRange, TextSize};
use ncc_syntax::{limit::next_line_start, visible};

use crate::positions::{Columns, TextIndex};

/// Lines of this many bytes or fewer are shown whole.
const WHOLE_LINE_BYTES: usize = 200;
/// Characters shown on each side of a marked place in a line cut to windows.
const CONTEXT_CHARS: usize = 40;

/// A file reports point into: its name, text and where its marked places are.
pub(crate) struct MarkedFile<'a> {
    pub name: &'a str,
    pub text: &'a str,
    /// Starts and ends of the marked ranges, in any order.
    pub marks: Vec<usize>,
}

/// The files of a report run as ariadne's cache, each prepared when first
/// shown; ariadne names them by their index.
pub(crate) struct Shown<'a> {
    files: Vec<MarkedFile<'a>>,
    prepared: HashMap<usize, ShownFile>,
}

/// A file as shown.
struct ShownFile {
    index: TextIndex,
    source: Source<String>,
    /// Per line, how many characters of the shown text come before it.
    line_chars: Vec<usize>,
    /// The lines cut to windows, with their pieces.
    cut: HashMap<u32, Vec<Piece>>,
}

/// A stretch of a file's line in its shown line.
struct Piece {
    /// Its column in the shown line.
    shown_column: u32,
    /// Its bytes in the file, and its column there.
    file: Range<usize>,
    file_column: u32,
}

/// A file of the report run, as ariadne names it: a marker that the places
/// it prints are found by (shown text never holds NUL).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct FileKey(usize);

impl fmt::Display for FileKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "\0{}\0", self.0)
    }
}

impl<'a> Shown<'a> {
    pub fn new(files: Vec<MarkedFile<'a>>) -> Shown<'a> {
        Shown { files, prepared: HashMap::new() }
    }

    /// The file named `name`, if it is one of the run's.
    pub fn key(&self, name: &str) -> Option<FileKey> {
        self.files.iter().position(|file| file.name == name).map(FileKey)
    }

    /// Where the range `range` of a file is in its shown text, in characters.
    pub fn span(&mut self, key: FileKey, range: TextRange) -> (FileKey, Range<usize>) {
        let file = self.prepare(key);
        let start = file.shown_char(range.start());
        let end = file.shown_char(range.end()).max(start);
        (key, start..end)
    }

    /// Drops a file's shown text: its reports are written.
    pub fn forget(&mut self, key: FileKey) {
        self.prepared.remove(&key.0);
    }

    fn prepare(&mut self, key: FileKey) -> &ShownFile {
        let file = &self.files[key.0];
        self.prepared.entry(key.0).or_insert_with(|| ShownFile::new(file))
    }

    /// `rendered` with the markers and shown columns of the places ariadne
    /// printed (`\0key\0:line:column`) replaced by the files' names and
    /// columns.
    pub fn restore_places(&self, rendered: &str) -> String {
        let mut out = String::with_capacity(rendered.len());
        let mut rest = rendered;
        while let Some(at) = rest.find('\0') {
            out.push_str(&rest[..at]);
            let after_marker = &rest[at + 1..];
            let found = after_marker.split_once('\0').and_then(|(key, after)| {
                let key = key.parse::<usize>().ok()?;
                Some((&self.files.get(key)?.name, self.prepared.get(&key), after))
            });
            let Some((name, file, after)) = found else {
                out.push_str(&visible::escaped("\0"));
                rest = after_marker;
                continue;
            };
            out.push_str(&visible::escaped(name));
            rest = after;
            let place = after.strip_prefix(':').and_then(|place| {
                let (line, place) = place.split_once(':')?;
                let digits = place.bytes().take_while(u8::is_ascii_digit).count();
                let column: u32 = place[..digits].parse().ok()?;
                let line_number: u32 = line.parse().ok()?;
                let column = file?.file_column(line_number.checked_sub(1)?, column.checked_sub(1)?)? + 1;
                Some((line_number, column, &place[digits..]))
            });
            if let Some((line, column, after)) = place {
                out.push_str(&format!(":{line}:{column}"));
                rest = after;
            }
        }
        out.push_str(rest);
        out
    }
}

impl Cache<FileKey> for Shown<'_> {
    type Storage = String;

    fn fetch(&mut self, key: &FileKey) -> Result<&Source<String>, impl fmt::Debug> {
        if key.0 >= self.files.len() {
            return Err("no such file");
        }
        Ok(&self.prepare(*key).source)
    }

    fn display<'b>(&self, key: &'b FileKey) -> Option<impl fmt::Display + 'b> {
        Some(*key)
    }
}

impl ShownFile {
    fn new(file: &MarkedFile<'_>) -> ShownFile {
        let index = TextIndex::new(file.text);
        let mut marks = file.marks.clone();
        marks.sort_unstable();
        marks.dedup();
        let bytes = file.text.as_bytes();
        let (mut shown, mut line_chars, mut cut) = (String::with_capacity(file.text.len()), Vec::new(), HashMap::new());
        let mut chars = 0;
        let mut start = 0;
        for line in 0.. {
            let next = next_line_start(bytes, start);
            let line_text = &file.text[start..next.unwrap_or(file.text.len())];
            let content = ["\r\n", "\n", "\r"].iter().find_map(|end| line_text.strip_suffix(end)).unwrap_or(line_text);
            let content = start..start + content.len();
            line_chars.push(chars);
            if content.len() <= WHOLE_LINE_BYTES {
                chars += push_shown(&mut shown, &file.text[content.clone()]);
            } else {
                let marked = &marks[marks.partition_point(|&m| m < content.start)..];
                let marked = &marked[..marked.partition_point(|&m| m <= content.end)];
                let pieces = windows(file.text, &content, marked, &index);
                chars += push_pieces(&mut shown, file.text, &content, &pieces);
                cut.insert(line, pieces);
            }
            chars += push_shown(&mut shown, &file.text[content.end..start + line_text.len()]);
            match next {
                Some(next) => start = next,
                None => break,
            }
        }
        ShownFile { index, source: Source::from(shown), line_chars, cut }
    }

    /// Where byte `at` of the file is in the shown text, in characters.
    fn shown_char(&self, at: TextSize) -> usize {
        let (line, column) = self.index.line_col(at, Columns::Characters);
        let column = match self.cut.get(&line) {
            None => column,
            Some(pieces) => {
                let at = usize::from(at);
                match pieces.iter().rev().find(|piece| piece.file.start <= at) {
                    Some(piece) if at <= piece.file.end => piece.shown_column + (column - piece.file_column),
                    // Between windows (no mark is): the window after it.
                    _ => pieces.iter().find(|piece| piece.file.start > at).map_or(column, |piece| piece.shown_column),
                }
            }
        };
        self.line_chars.get(line as usize).copied().unwrap_or_default() + column as usize
    }

    /// The file's column of column `column` of line `line` as shown (both
    /// 0-based).
    fn file_column(&self, line: u32, column: u32) -> Option<u32> {
        let Some(pieces) = self.cut.get(&line) else { return Some(column) };
        let piece = pieces.iter().rev().find(|piece| piece.shown_column <= column)?;
        Some(piece.file_column + (column - piece.shown_column))
    }
}

/// Windows of [`CONTEXT_CHARS`] around each of the `marked` places of the
/// line `content` (at least one, at its start), merged where they meet.
fn windows(text: &str, content: &Range<usize>, marked: &[usize], index: &TextIndex) -> Vec<Piece> {
    let back = |at: usize| {
        let before = text[content.start..at].char_indices().rev().nth(CONTEXT_CHARS - 1);
        before.map_or(content.start, |(i, _)| content.start + i)
    };
    let forward =
        |at: usize| text[at..content.end].char_indices().nth(CONTEXT_CHARS).map_or(content.end, |(i, _)| at + i);
    let mut ranges: Vec<Range<usize>> = Vec::new();
    for &at in marked.iter().chain(marked.is_empty().then_some(&content.start)) {
        let window = back(at)..forward(at);
        match ranges.last_mut() {
            Some(last) if window.start <= last.end => last.end = last.end.max(window.end),
            _ => ranges.push(window),
        }
    }
    let mut shown_column = 0;
    let mut left = content.start;
    ranges
        .into_iter()
        .map(|file| {
            if file.start > left {
                // The `…` before it.
                shown_column += 1;
            }
            let (_, file_column) = index.line_col(size(file.start), Columns::Characters);
            let piece = Piece { shown_column, file: file.clone(), file_column };
            shown_column += text[file.clone()].chars().count() as u32;
            left = file.end;
            piece
        })
        .collect()
}

/// The pieces of a cut line, with `…` where text is left out; returns the
/// characters pushed.
fn push_pieces(shown: &mut String, text: &str, content: &Range<usize>, pieces: &[Piece]) -> usize {
    let mut chars = 0;
    let mut left = content.start;
    for piece in pieces {
        if piece.file.start > left {
            shown.push('…');
            chars += 1;
        }
        chars += push_shown(shown, &text[piece.file.clone()]);
        left = piece.file.end;
    }
    if content.end > left {
        shown.push('…');
        chars += 1;
    }
    chars
}

/// Pushes `text` with each hidden character drawn as a visible one (one for
/// one, so columns stay); returns the characters pushed.
fn push_shown(shown: &mut String, text: &str) -> usize {
    let mut chars = 0;
    for c in text.chars() {
        // Line terminators stay: they end the shown lines where the file's end.
        let keep = matches!(c, '\n' | '\r') || !visible::is_hidden(c);
        shown.push(if keep { c } else { visible::picture(c) });
        chars += 1;
    }
    chars
}

fn size(offset: usize) -> TextSize {
    TextSize::try_from(offset).expect("texts are smaller than 4 GiB")
}

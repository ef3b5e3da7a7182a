//! Byte offsets to lines and columns, and back, in logarithmic time.
//!
//! Lines end at `\n`, `\r\n` or `\r`, as the parser and the protocol count
//! them (`ncc_syntax::limit`). Columns count characters in reports and
//! UTF-16 units in the protocol. The index keeps where lines start and
//! where each non-ASCII character is, with running sums of the bytes they
//! take beyond one, so a conversion is a few binary searches whatever the
//! line's length. (`line-index` scans a line's non-ASCII characters on each
//! conversion: quadratic on a long line of Czech text or of bytes read as
//! Kamenický.) It holds no text, so work that outlives an edit can keep it.

use ncc_analysis::{TextEdit, TextSize};
use ncc_syntax::limit::next_line_start;

/// What a column counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Columns {
    Characters,
    Utf16,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct TextIndex {
    len: TextSize,
    line_starts: Vec<TextSize>,
    /// Where each non-ASCII character starts, in order.
    wide: Vec<TextSize>,
    /// For each of those characters, the bytes beyond one that it and the
    /// ones before it take.
    extra: Vec<u32>,
    /// Where each character that takes two UTF-16 units starts.
    astral: Vec<TextSize>,
}

impl TextIndex {
    pub fn new(text: &str) -> TextIndex {
        let bytes = text.as_bytes();
        let mut line_starts = vec![TextSize::from(0)];
        let mut at = 0;
        while let Some(next) = next_line_start(bytes, at) {
            line_starts.push(size(next));
            at = next;
        }
        let (mut wide, mut extra, mut astral) = (Vec::new(), Vec::new(), Vec::new());
        let mut sum = 0;
        let mut from = 0;
        while from < bytes.len() {
            // Whole stretches of ASCII at a time.
            let stretch = &bytes[from..(from + 64).min(bytes.len())];
            let Some(skip) = (!stretch.is_ascii()).then(|| stretch.iter().position(|b| !b.is_ascii())).flatten() else {
                from += stretch.len();
                continue;
            };
            let start = from + skip;
            let c = text[start..].chars().next().expect("a character starts at a non-ASCII byte");
            sum += c.len_utf8() as u32 - 1;
            wide.push(size(start));
            extra.push(sum);
            if c.len_utf16() == 2 {
                astral.push(size(start));
            }
            from = start + c.len_utf8();
        }
        TextIndex { len: size(text.len()), line_starts, wide, extra, astral }
    }

    /// The index of `text`, which `edit` made from the text of `self`: the
    /// lines around the edit are read again, and the rest shifted. An edit
    /// of one character in a large file costs a copy of the index, not a
    /// scan of the text.
    pub fn edited(&self, edit: &TextEdit, text: &str) -> TextIndex {
        let (start, old_end) = (edit.delete.start(), edit.delete.end());
        let new_end = start + TextSize::of(&edit.insert);
        let shifted = |at: TextSize| at + new_end - old_end;
        // A line start depends on the byte before it and its own (`\r\n`):
        // those before the line the edit starts in stay, and so do those
        // past its end. The window between is read again from a line start.
        let from_line = self.line_starts.partition_point(|&s| s <= start).saturating_sub(2);
        let from = self.line_starts[from_line];
        let after = self.line_starts.partition_point(|&s| s <= old_end);
        let (to_old, to_new) = match self.line_starts.get(after) {
            Some(&to) => (to, shifted(to)),
            None => (self.len, size(text.len())),
        };
        let window = TextIndex::new(&text[usize::from(from)..usize::from(to_new)]);
        // The window's last line start is `to_new` when it is one.
        let moved_lines = (after + 1).min(self.line_starts.len());
        let line_starts = splice(&self.line_starts, from_line, &window.line_starts, from, moved_lines, shifted);

        let kept = self.wide.partition_point(|&w| w < from);
        let moved = self.wide.partition_point(|&w| w < to_old);
        let wide = splice(&self.wide, kept, &window.wide, from, moved, shifted);
        let sum_before = |k: usize| k.checked_sub(1).map_or(0, |k| self.extra[k]);
        let kept_sum = sum_before(kept);
        let window_sum = window.extra.last().map_or(0, |&e| e);
        let mut extra = self.extra[..kept].to_vec();
        extra.extend(window.extra.iter().map(|&e| e + kept_sum));
        extra.extend(self.extra[moved..].iter().map(|&e| e - sum_before(moved) + kept_sum + window_sum));
        let kept_astral = self.astral.partition_point(|&a| a < from);
        let moved_astral = self.astral.partition_point(|&a| a < to_old);
        let astral = splice(&self.astral, kept_astral, &window.astral, from, moved_astral, shifted);
        TextIndex { len: size(text.len()), line_starts, wide, extra, astral }
    }

    pub fn len(&self) -> TextSize {
        self.len
    }

    /// Where line `line` (0-based) starts.
    pub fn line_start(&self, line: u32) -> Option<TextSize> {
        self.line_starts.get(line as usize).copied()
    }

    /// The 0-based line and column of `offset` (clamped to the text; inside
    /// a character, the character's column).
    pub fn line_col(&self, offset: TextSize, columns: Columns) -> (u32, u32) {
        let offset = offset.min(self.len);
        let line = self.line_starts.partition_point(|&start| start <= offset) - 1;
        (line as u32, self.width(self.line_starts[line], offset, columns))
    }

    /// The offset of column `col` (UTF-16 units) of the line that runs from
    /// `start` to `end` (its terminator excluded): clamped to `end`, and
    /// inside a character moved to its start.
    pub fn offset_in_line(&self, start: TextSize, end: TextSize, col: u32) -> TextSize {
        let first = self.wide.partition_point(|&w| w < start);
        let last = self.wide.partition_point(|&w| w < end);
        let before = self.wide[first..last].partition_point(|&w| self.width(start, w, Columns::Utf16) <= col);
        let offset = match before.checked_sub(1).map(|k| first + k) {
            // ASCII up to the column.
            None => start + TextSize::from(col),
            Some(k) => {
                let at = self.wide[k];
                let rest = col - self.width(start, at, Columns::Utf16);
                let units = if self.astral.binary_search(&at).is_ok() { 2 } else { 1 };
                let bytes = self.extra[k] - k.checked_sub(1).map_or(0, |j| self.extra[j]) + 1;
                if rest < units { at } else { at + TextSize::from(bytes + rest - units) }
            }
        };
        offset.min(end)
    }

    /// How many characters or UTF-16 units lie between `from` and `to`.
    fn width(&self, from: TextSize, to: TextSize, columns: Columns) -> u32 {
        let extra_before = |at: TextSize| match self.wide.partition_point(|&w| w < at) {
            0 => 0,
            k => self.extra[k - 1],
        };
        let chars = u32::from(to - from) - (extra_before(to) - extra_before(from));
        match columns {
            Columns::Characters => chars,
            Columns::Utf16 => {
                let astral = |at: TextSize| self.astral.partition_point(|&a| a < at) as u32;
                chars + astral(to) - astral(from)
            }
        }
    }
}

/// The offsets `old[..kept]`, then those of `window` (relative to
/// `from`), then `old[moved..]` moved by the edit: one of an index's lists
/// after an edit, with the window read again.
fn splice(
    old: &[TextSize],
    kept: usize,
    window: &[TextSize],
    from: TextSize,
    moved: usize,
    shifted: impl Fn(TextSize) -> TextSize,
) -> Vec<TextSize> {
    let mut spliced = Vec::with_capacity(kept + window.len() + old.len() - moved);
    spliced.extend_from_slice(&old[..kept]);
    spliced.extend(window.iter().map(|&at| at + from));
    spliced.extend(old[moved..].iter().map(|&at| shifted(at)));
    spliced
}

fn size(offset: usize) -> TextSize {
    TextSize::try_from(offset).expect("texts are smaller than 4 GiB")
}

#[cfg(test)]
mod tests {
    use ncc_analysis::TextRange;
    use proptest::prelude::*;

    use super::*;

    /// Pieces that make line starts and wide characters appear, vanish and
    /// merge (`\r` then `\n`).
    const PIECES: &[&str] = &["N1 X2", "\n", "\r", "\r\n", "č", "𝄞", "€", " "];

    fn text() -> impl Strategy<Value = String> {
        prop::collection::vec(prop::sample::select(PIECES), 0..30).prop_map(|pieces| pieces.concat())
    }

    proptest! {
        // Cases are cheap, and a merged `\r\n` at the window's edge is rare.
        #![proptest_config(ProptestConfig::with_cases(5000))]

        #[test]
        fn an_edited_index_equals_the_index_of_the_edited_text(
            before in text(),
            insert in text(),
            (start, end) in (any::<prop::sample::Index>(), any::<prop::sample::Index>()),
        ) {
            // Edits start and end between characters.
            let bounds: Vec<usize> = before.char_indices().map(|(at, _)| at).chain([before.len()]).collect();
            let (start, end) = (start.get(&bounds), end.get(&bounds));
            let (start, end) = (*start.min(end), *start.max(end));
            let edit = TextEdit::replace(TextRange::new(size(start), size(end)), insert);
            let mut after = before.clone();
            edit.apply(&mut after);
            prop_assert_eq!(TextIndex::new(&before).edited(&edit, &after), TextIndex::new(&after));
        }
    }

    #[test]
    fn columns_count_characters_or_utf16_units() {
        // `č` takes two bytes, `𝄞` four (two UTF-16 units), `€` three.
        let text = "N1 (č𝄞)\r\nN2 €X1\rN3\n";
        let index = TextIndex::new(text);
        let at = |offset: u32, columns| index.line_col(offset.into(), columns);
        assert_eq!(at(6, Columns::Characters), (0, 5), "after `č`");
        assert_eq!(at(10, Columns::Characters), (0, 6));
        assert_eq!(at(10, Columns::Utf16), (0, 7));
        assert_eq!(at(8, Columns::Utf16), (0, 5), "inside `𝄞`: its start");
        assert_eq!(at(11, Columns::Utf16), (0, 8), "on the `\\r` of `\\r\\n`");
        assert_eq!(at(12, Columns::Utf16), (0, 9), "on its `\\n`");
        assert_eq!(at(19, Columns::Characters), (1, 4), "after `€`");
        assert_eq!(at(22, Columns::Characters), (2, 0), "after a lone `\\r`");
        assert_eq!(at(99, Columns::Characters), (3, 0), "past the end: the end");
        assert_eq!(index.line_start(2), Some(22.into()));
        assert_eq!(index.line_start(4), None);
    }

    #[test]
    fn offsets_of_utf16_columns_clamp_to_the_line() {
        let text = "N1 (č𝄞)\r\nN2 €X1\n";
        let index = TextIndex::new(text);
        let offset = |col: u32| u32::from(index.offset_in_line(0.into(), 11.into(), col));
        assert_eq!(offset(3), 3);
        assert_eq!(offset(5), 6, "after `č`");
        assert_eq!(offset(6), 6, "inside `𝄞`: its start");
        assert_eq!(offset(7), 10, "after `𝄞`");
        assert_eq!(offset(8), 11);
        assert_eq!(offset(99), 11, "past the line's end: its end");
        assert_eq!(u32::from(index.offset_in_line(13.into(), 21.into(), 4)), 19, "after `€`");
    }

    #[test]
    fn conversions_agree_on_every_offset_of_a_mixed_line() {
        let text: String = "aČ𝄞b€\u{0}".repeat(50);
        let index = TextIndex::new(&text);
        let end = index.len();
        for (offset, c) in text.char_indices() {
            let offset = size(offset);
            let (_, chars) = index.line_col(offset, Columns::Characters);
            assert_eq!(chars as usize, text[..usize::from(offset)].chars().count());
            let (_, units) = index.line_col(offset, Columns::Utf16);
            assert_eq!(units as usize, text[..usize::from(offset)].encode_utf16().count());
            assert_eq!(index.offset_in_line(0.into(), end, units), offset, "{c:?}");
        }
    }
}

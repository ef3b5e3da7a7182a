//! Renumbering: new block numbers in file order, and every reference to a
//! block rewritten to the number its block gets, so the program does what
//! it did. Each dialect says which blocks are numbered and which words
//! lead to them, resolved as its control resolves them
//! ([`Numbering`]); where a target is computed, missing or ambiguous, it
//! refuses instead, since the new numbers could change where it leads.

use ncc_catalog::{Address, AddressRole, Catalogue};
use ncc_syntax::{TextEdit, TextRange};

/// A file's block numbers and the references to them.
#[derive(Debug, Default)]
pub(crate) struct Numbering {
    /// The digits of each block number, in file order.
    pub numbers: Vec<TextRange>,
    /// The digits of each reference, and the block number (an index into
    /// `numbers`) whose block it leads to.
    pub references: Vec<(TextRange, usize)>,
}

/// Why a file cannot be renumbered, and where.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RenumberError {
    pub range: TextRange,
    pub message: String,
}

impl RenumberError {
    pub(crate) fn new(range: TextRange, message: impl Into<String>) -> RenumberError {
        RenumberError { range, message: message.into() }
    }
}

/// The edits that give the numbered blocks of `numbering` the numbers
/// `start`, `start + step`, … and their references the same; `text` is the
/// file's. A number outside the block number address's range is refused.
pub(crate) fn edits(
    text: &str,
    catalogue: &Catalogue,
    numbering: &Numbering,
    start: u64,
    step: u64,
) -> Result<Vec<TextEdit>, RenumberError> {
    let address = catalogue.letter_with_role(AddressRole::BlockNumber).and_then(|letter| catalogue.address_of(letter));
    let (smallest, largest) = match address {
        Some(Address { bounds: Some((min, max)), .. }) => (min.max(0.0).ceil() as u64, max.max(0.0) as u64),
        Some(Address { int_digits: Some(digits), .. }) => (0, 10u64.saturating_pow(u32::from(*digits)) - 1),
        _ => (0, u64::MAX),
    };
    let count = numbering.numbers.len();
    if start < smallest && count > 0 {
        return Err(RenumberError::new(
            numbering.numbers[0],
            format!("block numbers start at {smallest}, so renumbering cannot start from {start}"),
        ));
    }
    let new_numbers: Vec<u64> = (0..count as u64)
        .map(|i| step.checked_mul(i).and_then(|offset| offset.checked_add(start)).filter(|&n| n <= largest))
        .collect::<Option<_>>()
        .ok_or_else(|| {
            let last = numbering.numbers.last().copied().unwrap_or_default();
            RenumberError::new(
                last,
                format!("{count} blocks from {start} by {step} pass the largest number, {largest}"),
            )
        })?;
    let mut edits: Vec<TextEdit> = numbering
        .numbers
        .iter()
        .zip(&new_numbers)
        .map(|(&range, &number)| (range, number))
        .chain(numbering.references.iter().map(|&(range, block)| (range, new_numbers[block])))
        .map(|(range, number)| TextEdit::replace(range, number.to_string()))
        .filter(|edit| text[edit.delete] != edit.insert)
        .collect();
    edits.sort_by_key(|edit| edit.delete.start());
    Ok(edits)
}

/// The digits in `range` of `text`: the last run of them (`N0010` →
/// `0010`, `GOTO 20` → `20`).
pub(crate) fn digits(text: &str, range: TextRange) -> Option<TextRange> {
    let written = &text[range];
    let end = written.rfind(|c: char| c.is_ascii_digit())? + 1;
    let start = written[..end].rfind(|c: char| !c.is_ascii_digit()).map_or(0, |at| at + 1);
    Some(TextRange::new(range.start() + offset(start), range.start() + offset(end)))
}

fn offset(at: usize) -> ncc_syntax::TextSize {
    ncc_syntax::TextSize::try_from(at).expect("texts are smaller than 4 GiB")
}

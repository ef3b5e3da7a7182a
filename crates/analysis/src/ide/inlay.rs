//! Inlay hints: the value a parameter assignment stores.
//!
//! A value written without a decimal point counts thousandths, so
//! `R1=864` stores 0.864 and shows `= 0.864`; `R1=0.864` and `R1=864.`
//! need no hint, nor does zero. The hint shows the stored value, which is
//! what a coordinate reads in mm (or degrees, on a rotary axis); F and the
//! dimensionless addresses (S, T, G, M) read the digits as written
//! (`R24=100`, `FR24` is F100), which the tooltip, the catalogue's rule
//! for R, explains.
//!
//! Values at the places a parameter is used (`XR12`) are left to hover:
//! they need the flow walk's state at every block of the range.

use ncc_catalog::AddressRole;
use ncc_syntax::{TextRange, TextSize};

use crate::{
    cnc8x6::checks::block::parameter_raw,
    cnc8x6::chunks,
    cnc8x6::flow::show_thousandths,
    db::{self, Db, Settings, SourceFile},
    lower::Value,
};

/// A label shown in the text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InlayHint {
    /// Where the label goes: after the text it describes.
    pub offset: TextSize,
    pub label: String,
    pub kind: InlayHintKind,
    /// Markdown shown on hover over the label.
    pub tooltip: Option<String>,
}

/// What an inlay hint tells.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InlayHintKind {
    /// The value a parameter assignment stores.
    ParameterValue,
    /// A block's predicted time, or the time at its end.
    BlockTime,
    /// A drop of the path speed at a block.
    SpeedBreak,
}

/// The hints of the blocks that `range` touches (all blocks without one).
pub(crate) fn inlay_hints(db: &dyn Db, file: SourceFile, range: Option<TextRange>) -> Vec<InlayHint> {
    let catalogue = Settings::get(db).dialect(db).catalogue();
    let tooltip = catalogue
        .letter_with_role(AddressRole::Parameter)
        .and_then(|letter| catalogue.address(&char::from(letter).to_string()))
        .and_then(|address| address.units.clone());
    let touches = |start: TextSize, end: TextSize| range.is_none_or(|r| start <= r.end() && r.start() <= end);
    let chunks = db::file_chunks(db, file);
    let file_end = TextSize::of(&**file.text(db));
    let mut hints = Vec::new();
    for (index, chunk) in chunks.iter().enumerate() {
        let chunk_end = chunks.get(index + 1).map_or(file_end, |next| next.offset);
        if !touches(chunk.offset, chunk_end) {
            continue;
        }
        for (offset, block) in chunks::lower_chunk(db, chunk.chunk) {
            let start = chunk.offset + offset;
            if !touches(start, start + block.len) {
                continue;
            }
            for assignment in &block.assignments {
                let (Some(Value::Literal(value)), Some(value_range)) = (&assignment.value, assignment.value_range)
                else {
                    continue;
                };
                let Some(raw) = parameter_raw(value).filter(|&raw| raw != 0 && !value.has_point()) else { continue };
                hints.push(InlayHint {
                    offset: start + value_range.end(),
                    label: format!("= {}", show_thousandths(raw)),
                    kind: InlayHintKind::ParameterValue,
                    tooltip: tooltip.clone(),
                });
            }
        }
    }
    hints
}

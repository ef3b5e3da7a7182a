//! Which CNC8x6 blocks renumbering changes, and what leads to them: the
//! `N` of every block, and the `L` of each `G73` jump (04 §1.6), resolved
//! in its unit as the control does. `G71 L`/`G79 L` name subprograms and
//! `G72 L` macrocycle files, not blocks, so they stay. A computed code
//! with an `L` (`GR24 L240`, which parameter arithmetic turns into `G73
//! L240` or `G78 L240`) is taken as the jump it is made for when the unit
//! has the block.

use nc_exec::cnc8x6::lower::Value;

use crate::{
    cnc8x6::{
        chunks,
        model::{self, TransferKind, transfer_kind},
    },
    db::{self, Db, SourceFile},
    ide::renumber::{Numbering, RenumberError, digits},
};

pub(crate) fn numbering(db: &dyn Db, file: SourceFile) -> Result<Numbering, RenumberError> {
    let text = file.text(db);
    let program = model::program(db, file);
    let mut numbering = Numbering::default();
    // The numbering index of each numbered block, by block index.
    let mut slots = vec![None; program.block_count()];
    let mut jumps = Vec::new();
    let mut index = 0;
    for chunk in db::file_chunks(db, file) {
        for (offset, block) in chunks::lower_chunk(db, chunk.chunk) {
            let at = chunk.offset + offset;
            if let Some(number) = block.number.filter(|number| number.value.is_some())
                && let Some(range) = digits(text, number.range + at)
            {
                slots[index] = Some(numbering.numbers.len());
                numbering.numbers.push(range);
            }
            let jump = transfer_kind(&block).is_some_and(|(kind, _)| kind == TransferKind::Jump);
            let computed_code = block.words_with(b'G').any(|word| matches!(word.value, Some(Value::Parameter { .. })));
            if (jump || computed_code)
                && let Some(label) = block.words_with(b'L').next()
            {
                let range = label.range + at;
                match &label.value {
                    Some(Value::Literal(value)) => {
                        let target = value.scaled(0).and_then(|n| u32::try_from(n).ok());
                        jumps.push((index, jump, range, target));
                    }
                    Some(Value::Parameter { .. }) => {
                        return Err(RenumberError::new(
                            range,
                            "the jump's target is a parameter, known only when the program runs: renumbering could break it",
                        ));
                    }
                    None => {}
                }
            }
            index += 1;
        }
    }
    for (from, jump, range, target) in jumps {
        let block = target.and_then(|number| program.jump_target(from, number));
        match block.and_then(|block| slots[block]) {
            Some(slot) => numbering.references.push((digits(text, range).unwrap_or(range), slot)),
            None if jump => {
                return Err(RenumberError::new(
                    range,
                    "no block of the jump's unit has this number: renumbering could make it lead somewhere",
                ));
            }
            None => {}
        }
    }
    Ok(numbering)
}

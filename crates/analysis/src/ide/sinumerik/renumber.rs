//! Which Sinumerik blocks renumbering changes, and what leads to them: the
//! `N` (or `:`) number of every numbered block, and each GOTO, GOTOF,
//! GOTOB and GOTOC to a block number, resolved in its direction as the
//! control searches. Labels stay as they are. A jump whose target is a
//! string computed at run time (`GOTOF "N"<<R3`) could name any block, so a
//! file with one is not renumbered.

use nc_exec::sinumerik::program::Resolved;

use super::navigation::{Symbol, jump_target, occurrences};
use crate::{
    db::{Db, SourceFile},
    ide::{
        references::ReferenceKind,
        renumber::{Numbering, RenumberError, digits},
    },
    sinumerik::model::file_model,
};

pub(crate) fn numbering(db: &dyn Db, file: SourceFile) -> Result<Numbering, RenumberError> {
    let text = file.text(db);
    let model = file_model(db, file);
    if let Some(site) = model.model.jumps.iter().find(|site| site.resolved == Resolved::Computed) {
        return Err(RenumberError::new(
            site.jump.range + model.ranges[site.block].start(),
            "the jump's target is computed when the program runs: renumbering could break it",
        ));
    }
    let mut numbering = Numbering::default();
    let mut slots = vec![None; model.ranges.len()];
    let numbers = occurrences(db, file).iter().filter(|o| matches!(o.symbol, Symbol::BlockNumber(_)));
    for occurrence in numbers.clone().filter(|o| o.kind == ReferenceKind::Definition) {
        if let Some(range) = digits(text, occurrence.range) {
            slots[occurrence.block] = Some(numbering.numbers.len());
            numbering.numbers.push(range);
        }
    }
    for jump in numbers.filter(|o| o.kind == ReferenceKind::Jump) {
        let slot = jump_target(model, jump).and_then(|block| slots[block]);
        match (digits(text, jump.range), slot) {
            (Some(range), Some(slot)) => numbering.references.push((range, slot)),
            _ => {
                return Err(RenumberError::new(
                    jump.range,
                    "no block in the jump's direction has this number: renumbering could make it lead somewhere",
                ));
            }
        }
    }
    Ok(numbering)
}

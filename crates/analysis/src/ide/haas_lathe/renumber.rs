//! Which Haas blocks renumbering changes, and what leads to them: the `N`
//! of every numbered block, and the P/Q of G70–G73, the P of M97 and the
//! target of GOTO, resolved in their program by the program model. M98
//! and G65 call programs, not blocks, so they stay. `M99 P` returns to a
//! block of whichever program called, perhaps in another file, so a file
//! with one is not renumbered.

use nc_exec::haas_lathe::program::{Finding, Reference, ReferenceKind, Target};

use crate::{
    db::{Db, SourceFile},
    haas_lathe::model::file_model,
    ide::renumber::{Numbering, RenumberError, digits},
};

pub(crate) fn numbering(db: &dyn Db, file: SourceFile) -> Result<Numbering, RenumberError> {
    let text = file.text(db);
    let model = file_model(db, file);
    let mut numbering = Numbering::default();
    let mut slots = vec![None; model.count()];
    for (index, block) in model.blocks_from(0).enumerate() {
        if let Some(number) = block.number.filter(|number| number.value.is_some())
            && let Some(range) = digits(text, model.in_file(index, number.range))
        {
            slots[index] = Some(numbering.numbers.len());
            numbering.numbers.push(range);
        }
        if block.has_code(b'M', 99)
            && let Some(range) = model.word_range(index, b'P')
        {
            return Err(RenumberError::new(
                range,
                "`M99 P` returns to a block of the calling program, which may be another file's: renumber by hand",
            ));
        }
    }
    let refused = |reference: Reference, why: &str| RenumberError::new(model.reference_range(reference), why);
    for finding in &model.model.findings {
        match finding {
            Finding::Resolved { reference, target: Target::Block(block) } if names_a_block(reference) => {
                let range = model.reference_range(*reference);
                if let (Some(range), Some(slot)) = (digits(text, range), slots[*block]) {
                    numbering.references.push((range, slot));
                }
            }
            Finding::ComputedTarget(reference) if names_a_block(reference) => {
                return Err(refused(
                    *reference,
                    "the target is computed when the program runs: renumbering could break it",
                ));
            }
            Finding::TargetNotFound { reference, .. } if names_a_block(reference) => {
                return Err(refused(
                    *reference,
                    "no block of the program has this number: renumbering could make it lead somewhere",
                ));
            }
            Finding::AmbiguousTarget { reference, .. } => {
                return Err(refused(
                    *reference,
                    "several blocks of the program have this number: number them apart first",
                ));
            }
            _ => {}
        }
    }
    Ok(numbering)
}

/// Whether `reference` names a block (not a program).
fn names_a_block(reference: &Reference) -> bool {
    !matches!(reference.kind, ReferenceKind::ProgramCall | ReferenceKind::MacroCall)
}

//! Completion in a CNC8x6 file: the codes and addresses every dialect
//! completes ([`Site`]), and
//!
//! * in the `L` of a call or jump, its targets: the file's subprograms
//!   (`G71`), the workspace's macrocycle files (`G72`), the numbered
//!   blocks of the unit (`G73`);
//! * after `R`, the parameters with their values before the block.
//!
//! Only the parameter list needs the flow walk's state: it asks
//! [`flow::states_before`] once per request, so its cost is that of one
//! walk of the file (less once the walk keeps checkpoints). The rest reads
//! the block, the program model and the catalogue.

use ncc_catalog::{AddressRole, Catalogue, Item, ParameterRange, ParameterStatus};
use ncc_syntax::{Dialect, TextRange, TextSize};

use crate::{
    cnc8x6::flow::{self, show_thousandths},
    cnc8x6::ide::arc_centre,
    cnc8x6::model::{self, TransferKind},
    db::{Db, Settings, SourceFile},
    ide::completion::{CompletionItem, CompletionKind, Site, Written, fenced},
    lower::{BlockData, Value, Word},
};

pub(crate) fn completions(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<CompletionItem> {
    let Some((index, start, block)) = crate::ide::block_at(db, file, offset) else { return Vec::new() };
    let at = offset - start;
    let in_comment = block.comments.iter().any(|c| c.range.start() < at && (at < c.range.end() || !c.closed));
    if in_comment {
        return Vec::new();
    }
    let written = written(db, &block, Dialect::Cnc8x6.catalogue());
    let site = Site::new(db, Dialect::Cnc8x6, start, written);
    let catalogue = site.catalogue;
    let request = Request { site, file, index };
    let site = &request.site;
    match Context::of(catalogue, &block, at, &file.text(db)[usize::from(start)..]) {
        Some(Context::Code { word }) => site.codes(word.letter, Some(word.range), word.range),
        Some(Context::Address { typed: Some(word) }) => site.addresses(Some(word.range), word.range),
        Some(Context::Address { typed: None }) => site.new_word(None, TextRange::empty(at)),
        Some(Context::Target { kind, word }) => request.targets(kind, word),
        Some(Context::Parameter { replace, assign }) => request.parameters(replace, assign),
        None => Vec::new(),
    }
}

/// What the cursor is writing.
enum Context<'a> {
    /// A G or M code.
    Code { word: &'a Word },
    /// A new word; `typed` is its letter, if written.
    Address { typed: Option<&'a Word> },
    /// The L of a call or jump, which names a target of `kind`.
    Target { kind: TransferKind, word: &'a Word },
    /// A parameter, referenced (`XR1`) or assigned (`R1=`); `replace` is
    /// relative to the block.
    Parameter { replace: TextRange, assign: bool },
}

impl<'a> Context<'a> {
    /// The context at `at` in `block`, whose text `text` starts.
    fn of(catalogue: &Catalogue, block: &'a BlockData, at: TextSize, text: &str) -> Option<Context<'a>> {
        let inside = |range: TextRange| range.start() < at && at <= range.end();
        if let Some(assignment) = block.assignments.iter().find(|a| inside(a.range)) {
            // The parameter's number, not its value.
            let replace = TextRange::new(assignment.range.start(), assignment.index_range.end());
            return (at <= replace.end()).then_some(Context::Parameter { replace, assign: false });
        }
        let Some(word) = block.words.iter().find(|w| inside(w.range)) else {
            return Some(Context::Address { typed: None });
        };
        let call = model::transfer_kind(block).map(|(kind, _)| kind);
        match (&word.value, catalogue.role_of(word.letter), call) {
            (Some(Value::Parameter { .. }), _, _) => {
                // `XR1`: from the `R` on.
                let typed = text.as_bytes().get(usize::from(word.range.start())..usize::from(at))?;
                let letter = typed.iter().rposition(|&b| catalogue.role_of(b) == Some(AddressRole::Parameter))?;
                let letter = word.range.start() + TextSize::try_from(letter).ok()?;
                let in_value = word.value_range.is_some_and(|value| value.start() <= letter);
                in_value
                    .then(|| Context::Parameter { replace: TextRange::new(letter, word.range.end()), assign: false })
            }
            (_, Some(AddressRole::Function), _) => Some(Context::Code { word }),
            (_, Some(AddressRole::Parameter), _) => Some(Context::Parameter { replace: word.range, assign: true }),
            (_, Some(AddressRole::Label), Some(kind)) => Some(Context::Target { kind, word }),
            (None, _, _) => Some(Context::Address { typed: Some(word) }),
            (Some(Value::Literal(_)), _, _) => None,
        }
    }
}

/// The block's words, codes and arc centre, as the neutral lists read them.
fn written(db: &dyn Db, block: &BlockData, catalogue: &Catalogue) -> Written {
    let codes = catalogue.function_letters().flat_map(|letter| block.codes(letter));
    Written {
        words: block.words.iter().map(|word| (word.letter, word.range)).collect(),
        codes: codes.map(|(number, word)| (word.letter, number, word.range)).collect(),
        centre: arc_centre(block, Settings::get(db).config(db)),
    }
}

/// One completion request in a CNC8x6 file: the block under the cursor.
struct Request<'a> {
    site: Site<'a>,
    file: SourceFile,
    index: usize,
}

impl Request<'_> {
    /// What the `L` of a call or jump may name.
    fn targets(&self, kind: TransferKind, typed: &Word) -> Vec<CompletionItem> {
        let db = self.site.db;
        let program = model::program(db, self.file);
        let item = |number: u32, kind: CompletionKind, (detail, documentation): (String, Option<String>)| {
            self.site.item(format!("L{number}"), kind, detail, documentation, typed.range)
        };
        match kind {
            TransferKind::Subprogram => {
                let own = program.unit_of(self.index).map(|unit| unit.blocks.start);
                program
                    .units
                    .iter()
                    .filter(|unit| Some(unit.blocks.start) != own)
                    .filter_map(|unit| {
                        let text = unit_text(db, self.file, program, unit.blocks.start);
                        Some(item(unit.number?, CompletionKind::Subprogram, text))
                    })
                    .collect()
            }
            TransferKind::Macrocycle => {
                let mut files: Vec<(u32, SourceFile)> =
                    model::macrocycles(db).iter().filter_map(|(&n, files)| Some((n, *files.first()?))).collect();
                files.sort_by_key(|&(number, _)| number);
                files
                    .into_iter()
                    .map(|(number, macro_file)| {
                        let macro_program = model::program(db, macro_file);
                        let first = macro_program.units.first().map_or(0, |unit| unit.blocks.start);
                        let (detail, block) = unit_text(db, macro_file, macro_program, first);
                        let documentation = format!("`{}`\n\n{}", macro_file.path(db), block.unwrap_or_default());
                        item(number, CompletionKind::Macrocycle, (detail, Some(documentation)))
                    })
                    .collect()
            }
            TransferKind::Jump => {
                let Some(unit) = program.unit_of(self.index) else { return Vec::new() };
                // Blocks numbered beyond L's range cannot be targets.
                let label = self.site.catalogue.addresses.iter().find(|a| a.role == AddressRole::Label);
                let max = label.and_then(|l| l.bounds).map_or(f64::MAX, |(_, max)| max);
                let text = self.file.text(db);
                program
                    .blocks_in(unit.blocks.clone())
                    .filter_map(|info| {
                        let number = u32::try_from(info.number?).ok().filter(|&n| f64::from(n) <= max)?;
                        let block = &text[usize::from(info.offset)..usize::from(info.end())];
                        let first_line = block.lines().next().unwrap_or_default().trim_end().to_owned();
                        Some(item(number, CompletionKind::Block, (first_line, Some(fenced(block)))))
                    })
                    .collect()
            }
        }
    }

    /// The parameters: those with a value before the block first, those
    /// the manual advises against last, reserved ones not at all.
    fn parameters(&self, replace: TextRange, assign: bool) -> Vec<CompletionItem> {
        let catalogue = self.site.catalogue;
        let states = flow::states_before(self.site.db, self.file, self.index);
        let mut items: Vec<(u8, CompletionItem)> = Vec::new();
        for number in 0..catalogue.parameters.count {
            let ranges: Vec<&ParameterRange> = catalogue.parameter_ranges_of(number).collect();
            let has = |status| ranges.iter().any(|range| range.status == status);
            if has(ParameterStatus::Reserved) {
                continue;
            }
            let mut values: Vec<String> = Vec::new();
            for (_, params) in &states {
                if let Some((raw, _)) = params.get(number) {
                    let value = show_thousandths(raw);
                    if !values.contains(&value) {
                        values.push(value);
                    }
                }
            }
            let detail = match ranges.first() {
                _ if !values.is_empty() => format!("= {}", values.join(" or ")),
                Some(range) => range.title.clone(),
                None => "Program parameter".to_owned(),
            };
            let mut documentation = Item::Parameter(number).markdown(catalogue);
            documentation.push_str(&crate::ide::values_text(number, states.iter().map(|(_, params)| params)));
            let tier = if has(ParameterStatus::NotRecommended) { 2 } else { u8::from(values.is_empty()) };
            let mut item =
                self.site.item(format!("R{number}"), CompletionKind::Parameter, detail, Some(documentation), replace);
            if assign {
                item.insert_text.push('=');
            }
            items.push((tier, item));
        }
        items.sort_by_key(|(tier, _)| *tier);
        items.into_iter().map(|(_, item)| item).collect()
    }
}

/// A unit's one-line description (the first comment of its start block,
/// else its first line) and its start block's text.
fn unit_text(db: &dyn Db, file: SourceFile, program: &model::Program, start: usize) -> (String, Option<String>) {
    let Some(info) = program.get_block(start) else { return (String::new(), None) };
    let text = &file.text(db)[usize::from(info.offset)..usize::from(info.end())];
    let comment = flow::lowered_block(db, file, start)
        .and_then(|(_, block)| block.comments.first().map(|c| c.body.trim().to_owned()))
        .filter(|body| !body.is_empty());
    let detail = comment.unwrap_or_else(|| text.lines().next().unwrap_or_default().trim_end().to_owned());
    (detail, Some(fenced(text)))
}

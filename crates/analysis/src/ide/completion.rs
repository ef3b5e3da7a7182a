//! Completion: what may be written at the cursor.
//!
//! The context comes from the lowered block under the cursor:
//!
//! * in a `G` or `M` word, the codes of the dialect, without those whose
//!   group a code of the block already holds and without planes the
//!   machine's axes do not have;
//! * where a word starts, the addresses, then those codes. The addresses
//!   the block's codes require and have not got come first (`L` after
//!   `G71`), then the arc centre of a `G02` or `G03` (named after the axes
//!   of the block's plane), then the others the codes read, then the rest;
//!   configured axes only, and no address twice;
//! * in the `L` of a call or jump, its targets: the file's subprograms
//!   (`G71`), the workspace's macrocycle files (`G72`), the numbered
//!   blocks of the unit (`G73`);
//! * after `R`, the parameters with their values before the block.
//!
//! Only the parameter list needs the flow walk's state: it asks
//! [`flow::states_before`] once per request, so its cost is that of one
//! walk of the file (less once the walk keeps checkpoints). The rest reads
//! the block, the program model and the catalogue.

use ncc_catalog::{AddressRole, Catalogue, Code, Item, ParameterRange, ParameterStatus};
use ncc_syntax::{TextRange, TextSize};

use crate::{
    Dialect,
    cnc8x6::flow::{self, show_thousandths},
    cnc8x6::model::{self, TransferKind},
    db::{Db, Settings, SourceFile},
    dialect,
    lower::{BlockData, Value, Word},
};

/// One thing that may be written at the cursor.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CompletionItem {
    /// What the list shows: `G01`, `X`, `L100`, `R12`.
    pub label: String,
    pub kind: CompletionKind,
    /// One line beside the label: a title, a value.
    pub detail: String,
    /// Markdown: the catalogue's hover text, a target's block.
    pub documentation: Option<String>,
    pub insert_text: String,
    /// The text the item replaces: what has been typed of the word.
    pub replace: TextRange,
}

/// What a completion item is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CompletionKind {
    /// A G or M code.
    Code,
    Address,
    /// A subprogram of the file, for `G71 L`.
    Subprogram,
    /// A macrocycle file of the workspace, for `G72 L`.
    Macrocycle,
    /// A numbered block of the unit, for `G73 L`.
    Block,
    Parameter,
}

/// The completions at `offset`, most relevant first.
pub(crate) fn completions(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<CompletionItem> {
    let Some((index, start, block)) = super::block_at(db, file, offset) else { return Vec::new() };
    let at = offset - start;
    let in_comment = block.comments.iter().any(|c| c.range.start() < at && (at < c.range.end() || !c.closed));
    if in_comment {
        return Vec::new();
    }
    let dialect = *Settings::get(db).dialect(db);
    let catalogue = dialect.catalogue();
    let request = Request { db, dialect, catalogue, file, index, start, block: &block };
    match Context::of(catalogue, &block, at, &file.text(db)[usize::from(start)..]) {
        Some(Context::Code { word }) => request.codes(word.letter, Some(word), word.range),
        Some(Context::Address { typed: Some(word) }) => request.addresses(Some(word), word.range),
        // Nothing typed yet: the list must hold the codes too, for the
        // editor filters it as the word is typed.
        Some(Context::Address { typed: None }) => {
            let mut items = request.addresses(None, TextRange::empty(at));
            for letter in catalogue.function_letters() {
                items.extend(request.codes(letter, None, TextRange::empty(at)));
            }
            items
        }
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

/// One completion request: the block under the cursor.
struct Request<'a> {
    db: &'a dyn Db,
    dialect: Dialect,
    catalogue: &'static Catalogue,
    file: SourceFile,
    index: usize,
    /// Where the block starts in the file.
    start: TextSize,
    block: &'a BlockData,
}

impl Request<'_> {
    /// An item that inserts its label over `replace` (relative to the block).
    fn item(
        &self,
        label: String,
        kind: CompletionKind,
        detail: String,
        documentation: Option<String>,
        replace: TextRange,
    ) -> CompletionItem {
        CompletionItem { insert_text: label.clone(), label, kind, detail, documentation, replace: replace + self.start }
    }

    /// The codes of `letter` that the block can still take besides the
    /// one being typed.
    fn codes(&self, letter: u8, typed: Option<&Word>, replace: TextRange) -> Vec<CompletionItem> {
        let catalogue = self.catalogue;
        let config = Settings::get(self.db).config(self.db);
        let taken: Vec<&str> = self
            .block
            .codes(letter)
            .filter(|(_, word)| Some(word.range) != typed.map(|t| t.range))
            .filter_map(|(number, _)| catalogue.group_of(char::from(letter), number))
            .map(|group| group.id.as_str())
            .collect();
        let letter = char::from(letter);
        let mut codes: Vec<(u32, &Code)> = catalogue
            .codes
            .iter()
            .filter_map(|code| {
                ncc_catalog::split_code(&code.code).filter(|(l, _)| *l == letter).map(|(_, n)| (n, code))
            })
            .filter(|(_, code)| code.group.as_deref().is_none_or(|group| !taken.contains(&group)))
            // A plane the machine's axes do not form.
            .filter(|&(number, _)| dialect::code_fits_machine(self.dialect, letter, number, config))
            .collect();
        codes.sort_by_key(|&(number, _)| number);
        codes
            .into_iter()
            .map(|(_, code)| {
                let documentation = Item::Code(code).markdown(catalogue);
                self.item(code.code.clone(), CompletionKind::Code, code.title.clone(), Some(documentation), replace)
            })
            .collect()
    }

    /// The addresses a new word may have: those the block's codes require
    /// first, then an arc's centre, then the others the codes read, then
    /// the rest.
    fn addresses(&self, typed: Option<&Word>, replace: TextRange) -> Vec<CompletionItem> {
        let catalogue = self.catalogue;
        let config = Settings::get(self.db).config(self.db);
        let block = self.block;
        let written =
            |letter: u8| block.words.iter().any(|w| w.letter == letter && Some(w.range) != typed.map(|t| t.range));
        let codes: Vec<&Code> = catalogue
            .function_letters()
            .flat_map(|letter| block.codes(letter).filter_map(move |(n, _)| catalogue.code(char::from(letter), n)))
            .collect();
        let required: Vec<&str> = codes.iter().flat_map(|code| code.requires.iter().map(String::as_str)).collect();
        let read: Vec<&str> = codes.iter().flat_map(|code| code.allows.iter().map(String::as_str)).collect();
        let centre = dialect::arc_centre(self.dialect, block, config);
        let mut items: Vec<(u8, CompletionItem)> = Vec::new();
        for address in &catalogue.addresses {
            let Some(&letter) = address.letter.as_bytes().first() else { continue };
            let repeats = matches!(address.role, AddressRole::Function | AddressRole::Parameter);
            let writable = !matches!(
                address.role,
                AddressRole::BlockNumber
                    | AddressRole::BlockSkip
                    | AddressRole::ProgramNumber
                    | AddressRole::ProgramEnd
            );
            let configured = address.role != AddressRole::Axis || config.machine.is_axis(letter);
            if !writable || !configured || (!repeats && written(letter)) {
                continue;
            }
            let name = address.letter.as_str();
            let centre = centre.iter().find(|(l, _)| *l == letter).map(|(_, detail)| detail);
            let tier = if required.contains(&name) {
                0
            } else if centre.is_some() {
                1
            } else if read.contains(&name) {
                2
            } else {
                3
            };
            let detail = centre.cloned().unwrap_or_else(|| address.title.clone());
            let documentation = Item::Address(address).markdown(catalogue);
            items.push((
                tier,
                self.item(address.letter.clone(), CompletionKind::Address, detail, Some(documentation), replace),
            ));
        }
        items.sort_by_key(|(tier, _)| *tier);
        items.into_iter().map(|(_, item)| item).collect()
    }

    /// What the `L` of a call or jump may name.
    fn targets(&self, kind: TransferKind, typed: &Word) -> Vec<CompletionItem> {
        let db = self.db;
        let program = model::program(db, self.file);
        let item = |number: u32, kind: CompletionKind, (detail, documentation): (String, Option<String>)| {
            self.item(format!("L{number}"), kind, detail, documentation, typed.range)
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
                let label = self.catalogue.addresses.iter().find(|a| a.role == AddressRole::Label);
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
        let catalogue = self.catalogue;
        let states = flow::states_before(self.db, self.file, self.index);
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
            documentation.push_str(&super::values_text(number, states.iter().map(|(_, params)| params)));
            let tier = if has(ParameterStatus::NotRecommended) { 2 } else { u8::from(values.is_empty()) };
            let mut item =
                self.item(format!("R{number}"), CompletionKind::Parameter, detail, Some(documentation), replace);
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

/// Program text as a Markdown code block.
fn fenced(text: &str) -> String {
    let longest = text.split(|c| c != '`').map(str::len).max().unwrap_or(0);
    let fence = "`".repeat(longest.max(2) + 1);
    format!("{fence}text\n{}\n{fence}", text.trim_end())
}

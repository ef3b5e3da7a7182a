//! Completion: what may be written at the cursor.
//!
//! Each dialect reads the context from the lowered block under the cursor
//! (`super::cnc8x6::completion`, `super::haas_lathe::completion`); the
//! lists every dialect has are here ([`Site`]):
//!
//! * in a `G` or `M` word, the codes of the dialect, without those whose
//!   group a code of the block already holds and without planes the
//!   machine's axes do not have;
//! * where a word starts, the addresses, then those codes. The addresses
//!   the block's codes require and have not got come first (`L` after
//!   `G71`), then the arc centre of a `G02` or `G03` (named after the axes
//!   of the block's plane), then the others the codes read, then the rest;
//!   configured axes only, and no address twice.

use ncc_catalog::{AddressRole, Catalogue, Code, Item};
use ncc_syntax::{TextRange, TextSize};

use super::{cnc8x6, haas_lathe, sinumerik};
use crate::{
    Dialect,
    db::{Db, Settings, SourceFile},
    dialect,
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
    /// Whether `insert_text` is a snippet, with `${1:name}` placeholders
    /// for the editor to fill.
    pub snippet: bool,
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
    /// A numbered block: of the unit, for `G73 L`; of the program, for a
    /// Haas contour's P and Q, `M97 P` and `GOTO`.
    Block,
    /// A Haas program of the file or the workspace, for `M98 P` and `G65 P`.
    Program,
    /// A CNC8x6 parameter (`R12`) or a Haas macro variable (`#101`).
    Parameter,
    /// A word of a Haas macro statement or operator: `IF`, `WHILE`, `EQ`.
    Keyword,
    /// A Haas macro function: `SIN`, `SQRT`.
    Function,
    /// A Sinumerik user variable (`DEF`, a PROC parameter) or system
    /// variable (`$P_F`).
    Variable,
    /// A Sinumerik label, after a jump.
    Label,
}

/// What the lists of codes and addresses read of the block under the
/// cursor, in any dialect.
#[derive(Debug, Default)]
pub(crate) struct Written {
    /// Each word's letter and range in the block.
    pub words: Vec<(u8, TextRange)>,
    /// The codes written as literals: letter, number and the word's range.
    pub codes: Vec<(u8, u32, TextRange)>,
    /// What the centre words mean, by letter, when the block draws an arc.
    pub centre: Vec<(u8, String)>,
}

/// The completions at `offset`, most relevant first.
pub(crate) fn completions(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<CompletionItem> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => cnc8x6::completion::completions(db, file, offset),
        Dialect::HaasLathe => haas_lathe::completion::completions(db, file, offset),
        Dialect::Sinumerik => sinumerik::completions(db, file, offset),
    }
}

/// The block under the cursor, as every dialect's lists read it.
pub(crate) struct Site<'a> {
    pub db: &'a dyn Db,
    pub dialect: Dialect,
    pub catalogue: &'static Catalogue,
    /// Where the block starts in the file.
    pub start: TextSize,
    pub written: Written,
}

impl<'a> Site<'a> {
    pub fn new(db: &'a dyn Db, dialect: Dialect, start: TextSize, written: Written) -> Site<'a> {
        Site { db, dialect, catalogue: dialect.catalogue(), start, written }
    }

    /// An item that inserts its label over `replace` (relative to the block).
    pub fn item(
        &self,
        label: String,
        kind: CompletionKind,
        detail: String,
        documentation: Option<String>,
        replace: TextRange,
    ) -> CompletionItem {
        let replace = replace + self.start;
        CompletionItem { insert_text: label.clone(), label, kind, detail, documentation, snippet: false, replace }
    }

    /// Where a new word starts (`typed`, its letter if written): the
    /// addresses, and the codes, for the editor filters the list as the
    /// word is typed.
    pub fn new_word(&self, typed: Option<TextRange>, replace: TextRange) -> Vec<CompletionItem> {
        let mut items = self.addresses(typed, replace);
        for letter in self.catalogue.function_letters() {
            items.extend(self.codes(letter, None, replace));
        }
        items
    }

    /// The codes of `letter` that the block can still take besides the
    /// one being typed (the word at `typed`).
    pub fn codes(&self, letter: u8, typed: Option<TextRange>, replace: TextRange) -> Vec<CompletionItem> {
        let catalogue = self.catalogue;
        let config = Settings::get(self.db).config(self.db);
        let taken: Vec<&str> = self
            .written
            .codes
            .iter()
            .filter(|&&(l, _, range)| l == letter && Some(range) != typed)
            .filter_map(|&(_, number, _)| catalogue.group_of(char::from(letter), number))
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
    /// the rest; `typed` is the word being written.
    pub fn addresses(&self, typed: Option<TextRange>, replace: TextRange) -> Vec<CompletionItem> {
        let catalogue = self.catalogue;
        let config = Settings::get(self.db).config(self.db);
        let block = &self.written;
        let written = |letter: u8| block.words.iter().any(|&(l, range)| l == letter && Some(range) != typed);
        let codes: Vec<&Code> =
            block.codes.iter().filter_map(|&(letter, number, _)| catalogue.code(char::from(letter), number)).collect();
        let required: Vec<&str> = codes.iter().flat_map(|code| code.requires.iter().map(String::as_str)).collect();
        let read: Vec<&str> = codes.iter().flat_map(|code| code.allows.iter().map(String::as_str)).collect();
        let centre = &block.centre;
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
}

/// Program text as a Markdown code block.
pub(crate) fn fenced(text: &str) -> String {
    let longest = text.split(|c| c != '`').map(str::len).max().unwrap_or(0);
    let fence = "`".repeat(longest.max(2) + 1);
    format!("{fence}text\n{}\n{fence}", text.trim_end())
}

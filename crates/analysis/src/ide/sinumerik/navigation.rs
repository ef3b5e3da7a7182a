//! Go to definition, references and rename in a Sinumerik file: labels and
//! block numbers with the jumps to them, user variables with their DEF or
//! PROC parameter, R parameters, and programs called by name.
//!
//! Every name of the tree is classified once ([`occurrences`]); the
//! references of a thing are the occurrences of the same [`Symbol`], so
//! definition, references and rename agree. A jump goes where the program
//! model resolves it; a computed one (`GOTOF "N"<<R3`) has no target before
//! a run.
//!
//! Assumptions, where the manual is silent: a file is one scope, the names
//! of all its DEFs and PROC parameters one set; a program is found in the
//! workspace by its file's name, `NAME.SPF`, `NAME.MPF`, `_N_NAME_SPF` or
//! `_N_NAME_MPF`, in any case (004:1444-1456); a name written without DEF
//! and unknown to the catalogue (a global variable) has references but no
//! definition here; a `REPEAT` section's label is looked for before the
//! `REPEAT`, then after it.

use nc_exec::sinumerik::{
    lower::{Callee, Jump, JumpKind, JumpTarget, StatementKind},
    program::Resolved,
};
use ncc_catalog::AddressRole;
use ncc_syntax::{Dialect, SyntaxElement, SyntaxKind, SyntaxNode, TextEdit, TextRange, TextSize};

use super::{blocks, catalogue, line_range};
use crate::{
    cnc8x6::model::file_stem,
    db::{Db, Settings, SourceFile},
    ide::{
        HoverResult, NavigationTarget, Renaming,
        references::{Reference, ReferenceKind},
    },
    sinumerik::model::{FileModel, file_model},
};

/// What a name stands for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Symbol {
    /// A label, upper case.
    Label(String),
    /// A block number as a jump's target.
    BlockNumber(u64),
    /// A user variable or formal parameter, upper case.
    Variable(String),
    /// An R parameter.
    Parameter(u64),
    /// A program by the name its file has (`PROFIL` for `_N_PROFIL_SPF`).
    Program(String),
}

/// A name written in the file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Occurrence {
    pub symbol: Symbol,
    /// The name in the file.
    pub range: TextRange,
    pub kind: ReferenceKind,
    pub block: usize,
}

/// Every name of the file that stands for something, in order.
#[salsa::tracked(returns(ref))]
pub(crate) fn occurrences(db: &dyn Db, file: SourceFile) -> Vec<Occurrence> {
    let model = file_model(db, file);
    let root = file.parse(db).syntax_node();
    let mut found = Vec::new();
    for block in blocks(&root) {
        let Some(index) = model.block_starting_at(block.text_range().start()) else { continue };
        found.extend(block.descendants().filter_map(|node| occurrence(model, index, &node)));
    }
    found
}

/// The occurrence at `offset`: the name that holds it, else the one that
/// ends there (the cursor after a name's last letter).
pub(crate) fn occurrence_at(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<&Occurrence> {
    let all = occurrences(db, file);
    all.iter().find(|o| o.range.contains(offset)).or_else(|| all.iter().find(|o| o.range.end() == offset))
}

/// The occurrence `node` of block `index` is, if it names something.
fn occurrence(model: &FileModel, index: usize, node: &SyntaxNode) -> Option<Occurrence> {
    let parent = node.parent().map(|parent| parent.kind());
    let elements = || node.children_with_tokens();
    let (symbol, range, kind) = match node.kind() {
        SyntaxKind::LABEL => {
            let (name, range) = name_run(elements())?;
            (Symbol::Label(name), range, ReferenceKind::Definition)
        }
        SyntaxKind::BLOCK_NUMBER => {
            let number = elements().find(|e| e.kind() == SyntaxKind::NUMBER)?.as_token()?.text().parse().ok()?;
            let kind =
                if parent == Some(SyntaxKind::GOTO_STMT) { ReferenceKind::Jump } else { ReferenceKind::Definition };
            (Symbol::BlockNumber(number), node.text_range(), kind)
        }
        SyntaxKind::NAME_REF if parent == Some(SyntaxKind::GOTO_STMT) => {
            let (name, range) = name_run(elements())?;
            (Symbol::Label(name), range, ReferenceKind::Jump)
        }
        SyntaxKind::NAME_REF => {
            let (name, range) = name_run(elements())?;
            if name.starts_with('$') || (!is_declared(model, &name) && language_word(&name).is_some()) {
                return None;
            }
            (Symbol::Variable(name), range, access(node))
        }
        SyntaxKind::VAR_DECL | SyntaxKind::PARAM => {
            let (name, range) = declared(node)?;
            (Symbol::Variable(name), range, ReferenceKind::Definition)
        }
        SyntaxKind::PARAM_REF => {
            let number = elements().find(|e| e.kind() == SyntaxKind::NUMBER)?.as_token()?.text().parse().ok()?;
            (Symbol::Parameter(number), node.text_range(), access(node))
        }
        SyntaxKind::PROC_STMT | SyntaxKind::EXTERN_STMT => {
            let (name, range) = name_run(elements().skip(1))?;
            let kind = if node.kind() == SyntaxKind::PROC_STMT {
                ReferenceKind::Definition
            } else {
                ReferenceKind::Declaration
            };
            (Symbol::Program(program_key(&name)), range, kind)
        }
        SyntaxKind::CALL_STMT => {
            let (name, range) = name_run(elements())?;
            let relative = node.text_range() - model.ranges[index].start();
            let statement = model.block(index).statements.iter().find(|s| s.range.contains_range(relative))?;
            match &statement.kind {
                StatementKind::RepeatSection { start, end, .. } if *start == name || end.as_ref() == Some(&name) => {
                    (Symbol::Label(name), range, ReferenceKind::Jump)
                }
                StatementKind::Call(call) | StatementKind::ModalCall(Some(call)) => match &call.callee {
                    Callee::Program(called) | Callee::Cycle(called) if *called == name => {
                        (Symbol::Program(program_key(&name)), range, ReferenceKind::Call)
                    }
                    _ => return None,
                },
                _ => return None,
            }
        }
        _ => return None,
    };
    Some(Occurrence { symbol, range, kind, block: index })
}

/// The name a DEF's `VAR_DECL` or a PROC's parameter declares.
pub(super) fn declared(node: &SyntaxNode) -> Option<(String, TextRange)> {
    let elements = node.children_with_tokens();
    match node.kind() {
        SyntaxKind::VAR_DECL => name_run(elements),
        SyntaxKind::PARAM if node.parent().is_some_and(|parent| parent.kind() == SyntaxKind::PROC_STMT) => {
            name_run(elements.skip_while(|e| e.kind() != SyntaxKind::TYPE).skip(1))
        }
        _ => None,
    }
}

/// The name that starts the elements (after blanks), upper case: an
/// identifier, or a letter with its digits (`L1`, `R_1`).
pub(super) fn name_run(elements: impl Iterator<Item = SyntaxElement>) -> Option<(String, TextRange)> {
    let is_name = |e: &SyntaxElement| matches!(e.kind(), SyntaxKind::IDENT | SyntaxKind::LETTER | SyntaxKind::NUMBER);
    let mut tokens = elements.skip_while(|e| e.kind().is_trivia()).take_while(is_name).filter_map(|e| e.into_token());
    let first = tokens.next()?;
    if first.kind() == SyntaxKind::NUMBER {
        return None;
    }
    let mut name = first.text().to_ascii_uppercase();
    let mut range = first.text_range();
    for token in tokens {
        name.push_str(&token.text().to_ascii_uppercase());
        range = range.cover(token.text_range());
    }
    Some((name, range))
}

/// Whether the variable or parameter `node` (`A`, `A[1]`'s name) is
/// assigned: the target of `=`, a FOR's variable included.
fn access(node: &SyntaxNode) -> ReferenceKind {
    let place = match node.parent() {
        Some(parent) if parent.kind() == SyntaxKind::INDEX_EXPR && parent.first_child().as_ref() == Some(node) => {
            parent
        }
        _ => node.clone(),
    };
    match place.parent() {
        Some(assign) if assign.kind() == SyntaxKind::ASSIGN && assign.first_child() == Some(place) => {
            ReferenceKind::Write
        }
        _ => ReferenceKind::Read,
    }
}

/// Whether a DEF or a PROC parameter of the file declares `name`.
fn is_declared(model: &FileModel, name: &str) -> bool {
    model.model.definitions.iter().any(|definition| definition.declared.name == name)
        || model
            .model
            .procs
            .iter()
            .any(|proc| proc.declaration.parameters.iter().any(|parameter| parameter.name.as_deref() == Some(name)))
}

/// What the catalogue knows `name` (upper case) as, if anything: a
/// keyword, function, code, axis or other address, or cycle.
fn language_word(name: &str) -> Option<&'static str> {
    let catalogue = catalogue();
    if catalogue.keyword(name).is_some() {
        Some("a keyword")
    } else if catalogue.function(name).is_some() {
        Some("a predefined function")
    } else if catalogue.word_code(name).is_some() {
        Some("a code")
    } else if let Some(address) = catalogue.address(name) {
        Some(if address.role == AddressRole::Axis { "an axis" } else { "an address" })
    } else if catalogue.cycles_for(name).next().is_some() {
        Some("a cycle")
    } else {
        None
    }
}

/// A program's name without the control's prefix and suffix, upper case:
/// `PROFIL` for `_N_PROFIL_SPF` and for `/_N_SPF_DIR/_N_PROFIL_SPF`.
pub(crate) fn program_key(name: &str) -> String {
    let name = name.rsplit('/').next().unwrap_or(name).to_ascii_uppercase();
    let name = name.strip_prefix("_N_").unwrap_or(&name);
    name.strip_suffix("_SPF").or_else(|| name.strip_suffix("_MPF")).unwrap_or(name).to_owned()
}

/// The Sinumerik files of the workspace named after program `key`.
pub(crate) fn program_files(db: &dyn Db, key: &str) -> impl Iterator<Item = SourceFile> {
    Settings::get(db).files(db).iter().copied().filter(move |&file| {
        file.parse(db).dialect() == Dialect::Sinumerik && program_key(file_stem(file.path(db))) == key
    })
}

/// Block `index`'s line, `focus` in it selected.
fn target(db: &dyn Db, file: SourceFile, index: usize, focus: TextRange) -> NavigationTarget {
    let root = file.parse(db).syntax_node();
    let start = file_model(db, file).ranges[index].start();
    let range = blocks(&root)
        .find(|block| block.text_range().start() == start)
        .map_or(focus, |block| line_range(file.text(db), &block));
    NavigationTarget { file, range, focus }
}

pub(crate) fn goto_definition(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<NavigationTarget> {
    let Some(at) = occurrence_at(db, file, offset) else { return Vec::new() };
    let model = file_model(db, file);
    let same =
        |kind: ReferenceKind| occurrences(db, file).iter().filter(move |o| o.symbol == at.symbol && o.kind == kind);
    let to = |o: &Occurrence| target(db, file, o.block, o.range);
    match &at.symbol {
        Symbol::Label(_) | Symbol::BlockNumber(_) if at.kind == ReferenceKind::Definition => vec![to(at)],
        Symbol::Label(_) | Symbol::BlockNumber(_) => match jump_target(model, at) {
            Some(block) => same(ReferenceKind::Definition).filter(|o| o.block == block).map(to).collect(),
            None => Vec::new(),
        },
        Symbol::Variable(_) => same(ReferenceKind::Definition).map(to).collect(),
        // The assignments: where a value can come from.
        Symbol::Parameter(_) => same(ReferenceKind::Write).map(to).collect(),
        Symbol::Program(key) => program_files(db, key)
            .filter_map(|other| {
                let model = file_model(db, other);
                let index = model.model.header().map_or(0, |header| header.block);
                let name = occurrences(db, other)
                    .iter()
                    .find(|o| o.block == index && o.kind == ReferenceKind::Definition && o.symbol == at.symbol);
                let focus =
                    name.map(|o| o.range).or_else(|| model.ranges.get(index).map(|r| TextRange::empty(r.start())))?;
                Some(target(db, other, index, focus))
            })
            .collect(),
    }
}

/// The block the jump or `REPEAT` section at `at` reaches.
pub(super) fn jump_target(model: &FileModel, at: &Occurrence) -> Option<usize> {
    let relative = at.range - model.ranges[at.block].start();
    let resolved = match model.model.jumps_from(at.block).find(|site| site.jump.range.contains_range(relative)) {
        Some(site) => site.resolved,
        None => {
            // A `REPEAT` section's label: before it, else after.
            let Symbol::Label(label) = &at.symbol else { return None };
            let jump = |kind| Jump { kind, target: Some(JumpTarget::Label(label.clone())), range: relative };
            match model.model.resolve(at.block, &jump(JumpKind::GotoB)) {
                Resolved::Block(block) => Resolved::Block(block),
                _ => model.model.resolve(at.block, &jump(JumpKind::GotoF)),
            }
        }
    };
    match resolved {
        Resolved::Block(block) => Some(block),
        _ => None,
    }
}

/// What the name at `offset` stands for: the lines that define it (a DEF,
/// a PROC, a label's block), and how often the file uses it. R
/// parameters are the catalogue's to describe.
pub(crate) fn hover(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<HoverResult> {
    let at = occurrence_at(db, file, offset)?;
    let (title, missing) = match &at.symbol {
        Symbol::Label(name) => (format!("label `{name}`"), "no block of the program has it: a jump to it fails"),
        Symbol::BlockNumber(number) => (format!("block `N{number}`"), "no block of the program has the number"),
        Symbol::Variable(name) => (
            format!("variable `{name}`"),
            "not declared in this file: global user data or a macro of the machine (`[sinumerik] globals` in ncc.toml)",
        ),
        Symbol::Program(name) => (format!("program `{name}`"), "no file of the workspace holds it"),
        Symbol::Parameter(_) => return None,
    };
    let mut markdown = format!("**{title}**");
    let definitions = goto_definition(db, file, offset);
    for definition in &definitions {
        let text = definition.file.text(db);
        let line = file_model(db, definition.file).line_at(definition.range.start());
        let place = if definition.file == file {
            format!("line {line}")
        } else {
            format!("{} line {line}", definition.file.path(db))
        };
        markdown.push_str(&format!("\n\n```sinumerik\n{}\n```\n{place}", &text[definition.range]));
    }
    if definitions.is_empty() {
        markdown.push_str(&format!("\n\n{missing}"));
    }
    let uses = references(db, file, offset, false).len();
    markdown.push_str(&format!("\n\n{uses} use{}", if uses == 1 { "" } else { "s" }));
    Some(HoverResult { range: at.range, markdown })
}

/// The occurrences of the thing at `offset`: of a program, in every file of
/// the workspace; of anything else, in the file.
pub(crate) fn references(db: &dyn Db, file: SourceFile, offset: TextSize, include_declaration: bool) -> Vec<Reference> {
    let Some(at) = occurrence_at(db, file, offset) else { return Vec::new() };
    let files: Vec<SourceFile> = match at.symbol {
        Symbol::Program(_) => Settings::get(db)
            .files(db)
            .iter()
            .copied()
            .filter(|other| other.parse(db).dialect() == Dialect::Sinumerik)
            .collect(),
        _ => vec![file],
    };
    let mut found: Vec<Reference> = files
        .into_iter()
        .flat_map(|other| {
            occurrences(db, other).iter().filter(|o| o.symbol == at.symbol).map(move |o| Reference {
                file: other,
                range: o.range,
                kind: o.kind,
            })
        })
        .collect();
    // The definition first, as the other dialects list it.
    found.sort_by_key(|r| r.kind != ReferenceKind::Definition);
    if !include_declaration {
        found.retain(|r| r.kind != ReferenceKind::Definition);
    }
    found
}

/// The longest name the control takes (004:1444-1450).
const MAX_NAME: usize = 31;

/// The name at `offset` that rename would change, or why there is none.
pub(crate) fn prepare_rename(db: &dyn Db, file: SourceFile, offset: TextSize) -> Result<TextRange, String> {
    renamed_at(db, file, offset).map(|at| at.range)
}

/// The edits that rename the thing at `offset` to `new_name`, or why they
/// cannot: a label or variable in the file; a program in every file of
/// the workspace, with its file.
pub(crate) fn rename(db: &dyn Db, file: SourceFile, offset: TextSize, new_name: &str) -> Result<Renaming, String> {
    let at = renamed_at(db, file, offset)?;
    check_new_name(db, file, &at.symbol, new_name)?;
    let Symbol::Program(key) = &at.symbol else {
        let edits = occurrences(db, file)
            .iter()
            .filter(|o| o.symbol == at.symbol)
            .map(|o| TextEdit::replace(o.range, new_name))
            .collect();
        return Ok(Renaming { edits: vec![(file, edits)], moved: Vec::new() });
    };
    let new_key = program_key(new_name);
    if let Some(taken) = program_files(db, &new_key).next() {
        return Err(format!("`{new_name}` is already a program of the workspace ({})", taken.path(db)));
    }
    let mut renaming = Renaming::default();
    for &other in Settings::get(db).files(db).iter().filter(|f| f.parse(db).dialect() == Dialect::Sinumerik) {
        let text = other.text(db);
        let edits: Vec<TextEdit> = occurrences(db, other)
            .iter()
            .filter(|o| o.symbol == at.symbol)
            .map(|o| TextEdit::replace(o.range, renamed_program(&text[o.range], new_name)))
            .collect();
        if !edits.is_empty() {
            renaming.edits.push((other, edits));
        }
    }
    for program in program_files(db, key) {
        let path = program.path(db);
        let stem = file_stem(path);
        let (directory, file_name) = path.split_at(path.rfind(['/', '\\']).map_or(0, |slash| slash + 1));
        let extension = &file_name[stem.len()..];
        let mut new_stem = renamed_program(stem, new_name);
        if stem.bytes().all(|b| !b.is_ascii_lowercase()) {
            new_stem.make_ascii_uppercase();
        }
        renaming.moved.push((program, format!("{directory}{new_stem}{extension}")));
    }
    Ok(renaming)
}

/// `new_name` written the way `old` names its program: bare, or with the
/// control's prefix and suffix (`_N_PROFIL_SPF`).
fn renamed_program(old: &str, new_name: &str) -> String {
    let upper = old.to_ascii_uppercase();
    let name = upper.rsplit('/').next().unwrap_or(&upper);
    let prefix = &old[..old.len() - name.len()];
    match (name.starts_with("_N_"), ["_SPF", "_MPF"].iter().find(|suffix| name.ends_with(*suffix))) {
        (true, Some(suffix)) => format!("{prefix}_N_{new_name}{}", &old[old.len() - suffix.len()..]),
        _ => format!("{prefix}{new_name}"),
    }
}

/// The name at `offset` if rename can change it: a label, or a variable
/// or parameter the file declares.
fn renamed_at(db: &dyn Db, file: SourceFile, offset: TextSize) -> Result<&Occurrence, String> {
    let at = occurrence_at(db, file, offset).ok_or_else(|| {
        "Nothing to rename here: user variables, PROC parameters, labels and programs can be renamed".to_owned()
    })?;
    let written = &file.text(db)[at.range];
    match &at.symbol {
        Symbol::Label(_) => Ok(at),
        Symbol::Variable(name) if is_declared(file_model(db, file), name) => Ok(at),
        Symbol::Variable(_) => Err(format!(
            "`{written}` is not declared in this file (no DEF or PROC parameter): it cannot be renamed here"
        )),
        Symbol::BlockNumber(_) => Err(format!("`{written}` is a block number: renumber the block instead")),
        Symbol::Parameter(_) => Err(format!("`{written}` is an R parameter: its number cannot be renamed")),
        Symbol::Program(key) if program_files(db, key).next().is_some() => Ok(at),
        Symbol::Program(_) => Err(format!(
            "`{written}` is not a program of the workspace (a cycle of the control, or a file not found): it cannot be renamed here"
        )),
    }
}

/// Refuses a name the control would not take (two letters, then letters,
/// digits and `_`, 31 characters at most: 004:1444-1450), a word of the
/// language or an axis, and a name the file already has.
fn check_new_name(db: &dyn Db, file: SourceFile, renamed: &Symbol, new_name: &str) -> Result<(), String> {
    let bytes = new_name.as_bytes();
    let valid = bytes.len() >= 2
        && bytes.len() <= MAX_NAME
        && bytes[..2].iter().all(u8::is_ascii_alphabetic)
        && bytes.iter().all(|&b| b.is_ascii_alphanumeric() || b == b'_');
    if !valid {
        return Err(format!(
            "`{new_name}` is not a valid name: two letters first, then letters, digits or `_`, \
             at most {MAX_NAME} characters"
        ));
    }
    let upper = new_name.to_ascii_uppercase();
    if let Some(word) = language_word(&upper) {
        return Err(format!("`{new_name}` is {word} of the control"));
    }
    let text = file.text(db);
    let taken = occurrences(db, file).iter().find(|o| {
        o.symbol != *renamed
            && match &o.symbol {
                Symbol::Label(name) | Symbol::Variable(name) => *name == upper,
                Symbol::Program(key) => *key == program_key(&upper),
                Symbol::BlockNumber(_) | Symbol::Parameter(_) => false,
            }
    });
    match taken {
        Some(o) => {
            let line = file_model(db, file).line_at(o.range.start());
            Err(format!("`{new_name}` is already a name in this file (`{}` on line {line})", &text[o.range]))
        }
        None => Ok(()),
    }
}

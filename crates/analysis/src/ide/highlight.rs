//! Semantic highlighting: every token of a file classified.
//!
//! The walk reads the green tree directly, the way lowering does, and looks
//! at nothing but the tokens and the catalogue: no program model, no flow.
//! It is linear in the text and cheap enough to run on every keystroke of a
//! program with a hundred thousand blocks.

use ncc_catalog::{AddressRole, Catalogue, Dialect};
use ncc_syntax::{NcLanguage, SyntaxKind, TextRange, TextSize};
use rowan::{GreenNodeData, NodeOrToken};
use rustc_hash::FxHashMap;

use crate::{
    cnc8x6::model::FileKind,
    db::{Db, Settings, SourceFile},
};

/// A classified piece of text. A file's ranges are sorted, never overlap,
/// never hold whitespace and never span a line break.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct HighlightRange {
    pub range: TextRange,
    pub kind: HighlightKind,
}

/// What a piece of text is. The set is finite: [`HighlightKind::all`] lists
/// every kind a dialect can produce, for an editor's legend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HighlightKind {
    /// A G or M code: `G01`, `M30`. `letter` is `b'G'` or `b'M'`; `group`
    /// is the index of the code's group in the catalogue's `groups` (whose
    /// ids are `G0` motion type, `G1` plane, `G3` radius compensation, `M2`
    /// spindle, …). It is `None` for a code outside the groups, and for the
    /// letter of a code given by a parameter (`GR21`), whose group is known
    /// only when the program runs.
    Code { letter: u8, group: Option<u8> },
    /// The letter of another address, by its role: an axis, the feed, the
    /// call target `L`, … Its value is a [`HighlightKind::Number`] or a
    /// parameter.
    Address(AddressRole),
    /// A letter the dialect has no address for.
    UnknownAddress,
    /// A block number word, `N10`.
    BlockNumber,
    /// A parameter: `R12` in `XR12` or `R1=R12` (`write: false`), or the
    /// target of an assignment, `R12` in `R12=5.` (`write: true`).
    Parameter { write: bool },
    /// A value, with its sign, and the program number of the header.
    Number,
    /// A comment, and text the control skips (before `%`, after `*`).
    Comment,
    /// `%`, `*`, the `$PC` of a fixed-cycle file and block skip `/`.
    Keyword,
    /// `=` of an assignment, the sign before a parameter (`X-R1`); the
    /// comparisons, `<<`, parentheses and the `:` of frames.
    Operator,
    /// Sinumerik: a string `"…"`.
    String,
    /// Sinumerik: a jump label, where it is defined (`write: true`,
    /// `LOOP1:`) or named by a jump (`GOTOF LOOP1`).
    Label { write: bool },
    /// Sinumerik: a command, cycle or subprogram called by name
    /// (`CYCLE81`, `TRAORI`, `PROFIL`), and a `PROC`'s name.
    Function,
    /// Sinumerik: a system variable, `$P_UIFR`.
    SystemVariable,
    /// Text the parser could not place (a syntax error covers it).
    Error,
}

impl HighlightKind {
    /// Every kind that highlighting can produce for a file of `dialect`:
    /// one code kind per G and M group of the catalogue (and one without a
    /// group per letter), one address kind per role of an address letter,
    /// and the fixed kinds.
    pub fn all(dialect: Dialect) -> Vec<HighlightKind> {
        let catalogue = dialect.catalogue();
        let mut kinds = Vec::new();
        let mut add = |kind| {
            if !kinds.contains(&kind) {
                kinds.push(kind);
            }
        };
        for address in &catalogue.addresses {
            let &[letter] = address.letter.as_bytes() else { continue };
            if !is_word_address(letter) {
                continue;
            }
            add(letter_kind(catalogue, letter, None));
            if address.role == AddressRole::Function {
                let groups =
                    catalogue.groups.iter().enumerate().filter(|(_, g)| g.id.as_bytes().first() == Some(&letter));
                for index in groups.filter_map(|(i, _)| u8::try_from(i).ok()) {
                    add(letter_kind(catalogue, letter, Some(index)));
                }
            }
        }
        for kind in [
            HighlightKind::UnknownAddress,
            HighlightKind::Parameter { write: false },
            HighlightKind::Parameter { write: true },
            HighlightKind::Number,
            HighlightKind::Comment,
            HighlightKind::Keyword,
            HighlightKind::Operator,
            HighlightKind::Error,
        ] {
            add(kind);
        }
        // The kinds of a language beyond addresses and codes.
        if !catalogue.keywords.is_empty() {
            for address in catalogue.addresses.iter().filter(|address| address.letter.len() > 1) {
                add(HighlightKind::Address(address.role));
            }
            for kind in [
                HighlightKind::String,
                HighlightKind::Label { write: true },
                HighlightKind::Label { write: false },
                HighlightKind::Function,
                HighlightKind::SystemVariable,
            ] {
                add(kind);
            }
        }
        kinds
    }
}

/// Whether the lexer reads `letter` as the address of a word.
fn is_word_address(letter: u8) -> bool {
    letter.is_ascii_alphabetic() || letter == b'&'
}

/// The kind of a word's address letter; `group` is a G or M code's.
/// Block numbers, codes and parameters colour the whole word, other
/// addresses only their letter.
fn letter_kind(catalogue: &Catalogue, letter: u8, group: Option<u8>) -> HighlightKind {
    let letter = letter.to_ascii_uppercase();
    match catalogue.role_of(letter) {
        Some(AddressRole::Function) => HighlightKind::Code { letter, group },
        Some(AddressRole::BlockNumber) => HighlightKind::BlockNumber,
        Some(AddressRole::Parameter) => HighlightKind::Parameter { write: false },
        Some(role) => HighlightKind::Address(role),
        None => HighlightKind::UnknownAddress,
    }
}

/// The ranges of `file`; with `within`, only those of the top-level items
/// (blocks, header, end) that overlap it.
pub(crate) fn highlight(db: &dyn Db, file: SourceFile, within: Option<TextRange>) -> Vec<HighlightRange> {
    let root = file.parse(db).green();
    let text = file.text(db);
    // Read from the text rather than the program model, which an edit
    // invalidates: a fixed-cycle file has `$PC` before its first block.
    let prelude = children(root, TextSize::from(0))
        .find(|(_, child)| matches!(kind(child.kind()), SyntaxKind::BLOCK | SyntaxKind::BLOCK_RUN));
    let prelude = &text[..prelude.map_or(text.len(), |(range, _)| usize::from(range.start()))];
    let mut walk = Walk {
        catalogue: Settings::get(db).dialect(db).catalogue(),
        groups: FxHashMap::default(),
        keyword_in_prelude: FileKind::of(file.path(db), prelude) == FileKind::CycleFile,
        in_prelude: true,
        // CAM output has about one piece per four bytes.
        out: Vec::with_capacity(if within.is_some() { 0 } else { text.len() / 4 }),
    };
    // An empty range still shows the item it is in.
    let skip = |range: TextRange| {
        within
            .is_some_and(|within| range.intersect(within).is_none_or(|common| common.is_empty() && !within.is_empty()))
    };
    for (range, child) in children(root, TextSize::from(0)) {
        if within.is_some_and(|within| range.start() > within.end()) {
            break;
        }
        let is_run = kind(child.kind()) == SyntaxKind::BLOCK_RUN;
        if is_run || kind(child.kind()) == SyntaxKind::BLOCK {
            walk.in_prelude = false;
        }
        match child {
            // Each block of a run is an item; a run away from the range is
            // skipped whole.
            NodeOrToken::Node(run) if is_run && !skip(range) => {
                for (range, block) in children(run, range.start()).filter(|(range, _)| !skip(*range)) {
                    walk.element(block, range, None, false);
                }
            }
            _ if is_run || skip(range) => {}
            _ => walk.element(child, range, None, false),
        }
    }
    walk.out
}

pub(super) fn kind(raw: rowan::SyntaxKind) -> SyntaxKind {
    <NcLanguage as rowan::Language>::kind_from_raw(raw)
}

pub(super) type GreenRef<'a> = NodeOrToken<&'a GreenNodeData, &'a rowan::GreenTokenData>;

/// The children of a green node with their ranges, `start` being the node's.
pub(super) fn children(node: &GreenNodeData, start: TextSize) -> impl Iterator<Item = (TextRange, GreenRef<'_>)> {
    let mut offset = start;
    node.children().map(move |child| {
        let range = TextRange::at(offset, child.text_len());
        offset = range.end();
        (range, child)
    })
}

struct Walk {
    catalogue: &'static Catalogue,
    /// The group of each code seen, by letter and number.
    groups: FxHashMap<(u8, u32), Option<u8>>,
    /// The file is a fixed-cycle file, whose `$PC` stands before its first
    /// block, usually in a comment.
    keyword_in_prelude: bool,
    in_prelude: bool,
    out: Vec<HighlightRange>,
}

impl Walk {
    /// Classifies a node or token outside words and assignments. `given`
    /// overrides the kind of every token in it; `merge` joins adjacent
    /// tokens of one kind, which is right inside an item (a header's `%-1`)
    /// but not between the items of a block.
    fn element(&mut self, element: GreenRef<'_>, range: TextRange, given: Option<HighlightKind>, merge: bool) {
        match element {
            NodeOrToken::Token(token) => {
                let token_kind = kind(token.kind());
                let Some(own) = token_kind_of(token_kind) else { return };
                match given.unwrap_or(own) {
                    HighlightKind::Comment if matches!(token_kind, SyntaxKind::PREAMBLE | SyntaxKind::TRAILER) => {
                        self.lines(range, token.text());
                    }
                    HighlightKind::Comment if self.in_prelude && self.keyword_in_prelude => {
                        self.with_keywords(range, token.text());
                    }
                    // An unclosed comment runs to the line's end, blanks included.
                    HighlightKind::Comment => {
                        let kept = token.text().trim_end_matches([' ', '\t']);
                        self.push(TextRange::at(range.start(), TextSize::of(kept)), HighlightKind::Comment, merge);
                    }
                    highlight => self.push(range, highlight, merge),
                }
            }
            NodeOrToken::Node(node) => match kind(node.kind()) {
                SyntaxKind::WORD => self.word(node, range.start()),
                SyntaxKind::PARAM_ASSIGN => self.assignment(node, range.start()),
                SyntaxKind::PARAM_REF => self.parameter(node, range.start()),
                SyntaxKind::PROGRAM_NUMBER => self.program_number(node, range.start()),
                SyntaxKind::VAR_REF => self.variable(node, range.start(), false),
                SyntaxKind::ASSIGN => self.variable_assignment(node, range.start()),
                SyntaxKind::NAME_REF => self.name(node, range.start(), false),
                SyntaxKind::INDEX_EXPR => self.indexed(node, range.start(), false),
                SyntaxKind::LABEL => self.nodes(node, range.start(), Some(HighlightKind::Label { write: true }), true),
                SyntaxKind::BLOCK_NUMBER => self.nodes(node, range.start(), Some(HighlightKind::BlockNumber), true),
                SyntaxKind::GOTO_STMT => self.jump(node, range.start()),
                SyntaxKind::CALL_STMT => self.call(node, range.start()),
                SyntaxKind::VAR_DECL => self.declared(node, range.start(), None),
                SyntaxKind::PARAM => self.declared(node, range.start(), Some(SyntaxKind::TYPE)),
                SyntaxKind::PROC_STMT | SyntaxKind::EXTERN_STMT | SyntaxKind::MACRO_DEF => {
                    self.procedure(node, range.start())
                }
                SyntaxKind::BIN_EXPR | SyntaxKind::PREFIX_EXPR | SyntaxKind::CALL_EXPR => {
                    self.operation(node, range.start())
                }
                SyntaxKind::ERROR => self.nodes(node, range.start(), Some(HighlightKind::Error), true),
                // The items of a block are separate; a header's, a block
                // skip's or the end's tokens form one item.
                SyntaxKind::BLOCK => self.nodes(node, range.start(), given, false),
                _ => self.nodes(node, range.start(), given, true),
            },
        }
    }

    fn nodes(&mut self, node: &GreenNodeData, start: TextSize, given: Option<HighlightKind>, merge: bool) {
        let first = self.out.len();
        for (range, child) in children(node, start) {
            self.element(child, range, given, merge && self.out.len() > first);
        }
    }

    /// Adds a range, joined to the previous one if `merge` allows it.
    fn push(&mut self, range: TextRange, kind: HighlightKind, merge: bool) {
        if merge
            && let Some(last) = self.out.last_mut()
            && last.kind == kind
            && last.range.end() == range.start()
        {
            last.range = last.range.cover(range);
            return;
        }
        self.out.push(HighlightRange { range, kind });
    }

    /// A word: its letter decides; the value of an ordinary address is a
    /// number, that of a code or block number is part of the word.
    fn word(&mut self, node: &GreenNodeData, start: TextSize) {
        let mut items = children(node, start).peekable();
        // The comma of a corner word, `,C1.`.
        if let Some((range, _)) = items.next_if(|(_, item)| kind(item.kind()) == SyntaxKind::COMMA) {
            self.out.push(HighlightRange { range, kind: HighlightKind::Operator });
        }
        let Some((letter_range, NodeOrToken::Token(letter))) = items.next() else {
            return self.nodes(node, start, Some(HighlightKind::Error), true);
        };
        let letter = letter.text().as_bytes()[0].to_ascii_uppercase();
        let group = match self.catalogue.role_of(letter) {
            Some(AddressRole::Function) => code_number(node).and_then(|number| self.group(letter, number)),
            _ => None,
        };
        let letter_kind = letter_kind(self.catalogue, letter, group);
        let value_kind = match letter_kind {
            HighlightKind::Address(_) | HighlightKind::UnknownAddress => HighlightKind::Number,
            whole_word => whole_word,
        };
        self.out.push(HighlightRange { range: letter_range, kind: letter_kind });
        self.value(items, value_kind);
    }

    /// `R12=5.`: the assigned parameter, `=`, then the value.
    fn assignment(&mut self, node: &GreenNodeData, start: TextSize) {
        let mut items = children(node, start);
        let first = self.out.len();
        for (range, item) in items.by_ref() {
            match kind(item.kind()) {
                SyntaxKind::EQ => {
                    self.out.push(HighlightRange { range, kind: HighlightKind::Operator });
                    break;
                }
                SyntaxKind::WHITESPACE => {}
                _ => self.push(range, HighlightKind::Parameter { write: true }, self.out.len() > first),
            }
        }
        self.value(items, HighlightKind::Number);
    }

    /// What follows an address or `=`: a sign and digits of `kind`, or a
    /// parameter, whose sign (`X-R1`) is an operator.
    fn value<'a>(&mut self, items: impl Iterator<Item = (TextRange, GreenRef<'a>)>, kind_of_digits: HighlightKind) {
        let mut sign: Option<usize> = None;
        for (range, item) in items {
            match (kind(item.kind()), item) {
                (SyntaxKind::WHITESPACE, _) => {}
                // Sinumerik's `X=…`.
                (SyntaxKind::EQ, _) => self.out.push(HighlightRange { range, kind: HighlightKind::Operator }),
                (SyntaxKind::PARAM_REF, NodeOrToken::Node(node)) => {
                    if let Some(sign) = sign {
                        self.out[sign].kind = HighlightKind::Operator;
                    }
                    self.parameter(node, range.start());
                }
                (SyntaxKind::PLUS | SyntaxKind::MINUS, _) => {
                    sign = Some(self.out.len());
                    self.out.push(HighlightRange { range, kind: kind_of_digits });
                }
                // A variable `#1` or an expression `[#1 + 2.]` as the value.
                (_, NodeOrToken::Node(_)) => {
                    if let Some(sign) = sign {
                        self.out[sign].kind = HighlightKind::Operator;
                    }
                    self.element(item, range, None, false);
                }
                _ => self.push(range, kind_of_digits, true),
            }
        }
    }

    /// `R` and the parameter number, used as a value.
    fn parameter(&mut self, node: &GreenNodeData, start: TextSize) {
        let first = self.out.len();
        for (range, item) in children(node, start) {
            if kind(item.kind()) != SyntaxKind::WHITESPACE {
                self.push(range, HighlightKind::Parameter { write: false }, self.out.len() > first);
            }
        }
    }

    /// `O1234`: the letter as a keyword, the program number as a number.
    fn program_number(&mut self, node: &GreenNodeData, start: TextSize) {
        for (range, item) in children(node, start) {
            match kind(item.kind()) {
                SyntaxKind::LETTER => self.push(range, HighlightKind::Keyword, false),
                _ => self.element(item, range, None, false),
            }
        }
    }

    /// `#12` (its `#` and number as one parameter), or `#[…]`, whose
    /// expression is highlighted as such.
    fn variable(&mut self, node: &GreenNodeData, start: TextSize, write: bool) {
        let first = self.out.len();
        for (range, item) in children(node, start) {
            match (kind(item.kind()), item) {
                (SyntaxKind::WHITESPACE, _) => {}
                (_, NodeOrToken::Node(_)) => self.element(item, range, None, false),
                _ => self.push(range, HighlightKind::Parameter { write }, self.out.len() > first),
            }
        }
    }

    /// `#1 = …`, `R1=…`, `NAME[1]=…`: the assigned variable, `=`, then
    /// the expression.
    fn variable_assignment(&mut self, node: &GreenNodeData, start: TextSize) {
        let mut assigned = false;
        for (range, item) in children(node, start) {
            match (kind(item.kind()), item) {
                (target_kind, NodeOrToken::Node(target)) if !assigned => {
                    assigned = true;
                    match target_kind {
                        SyntaxKind::VAR_REF => self.variable(target, range.start(), true),
                        SyntaxKind::PARAM_REF => {
                            self.tokens(target, range.start(), HighlightKind::Parameter { write: true })
                        }
                        SyntaxKind::NAME_REF => self.name(target, range.start(), true),
                        SyntaxKind::INDEX_EXPR => self.indexed(target, range.start(), true),
                        _ => self.element(item, range, None, false),
                    }
                }
                _ => self.element(item, range, None, false),
            }
        }
    }

    /// Every token of `node` as one item of `kind`.
    fn tokens(&mut self, node: &GreenNodeData, start: TextSize, kind: HighlightKind) {
        self.nodes(node, start, Some(kind), true);
    }

    /// A name used as a value or assigned: a system variable, a keyword
    /// (`TRUE`), an address (`X`, `CR`), else a variable.
    fn name(&mut self, node: &GreenNodeData, start: TextSize, write: bool) {
        for (range, item) in children(node, start) {
            match item {
                NodeOrToken::Token(token) if matches!(kind(token.kind()), SyntaxKind::IDENT | SyntaxKind::LETTER) => {
                    let highlight = self.name_kind(token.text(), write);
                    self.push(range, highlight, false);
                }
                _ => self.element(item, range, None, false),
            }
        }
    }

    fn name_kind(&self, name: &str, write: bool) -> HighlightKind {
        if name.starts_with('$') {
            return HighlightKind::SystemVariable;
        }
        if self.catalogue.keyword(name).is_some() {
            return HighlightKind::Keyword;
        }
        match self.catalogue.address(name) {
            Some(address) if address.letter.len() > 1 => HighlightKind::Address(address.role),
            Some(address) => letter_kind(self.catalogue, address.letter.as_bytes()[0], None),
            None => HighlightKind::Parameter { write },
        }
    }

    /// `A[1,2]`, `$P_UIFR[1,X,TR]`: the name, then the indices.
    fn indexed(&mut self, node: &GreenNodeData, start: TextSize, write: bool) {
        let mut named = false;
        for (range, item) in children(node, start) {
            match item {
                NodeOrToken::Token(token)
                    if !named && matches!(kind(token.kind()), SyntaxKind::IDENT | SyntaxKind::LETTER) =>
                {
                    named = true;
                    let highlight = self.name_kind(token.text(), write);
                    self.push(range, highlight, false);
                }
                NodeOrToken::Node(name) if !named && kind(name.kind()) == SyntaxKind::NAME_REF => {
                    named = true;
                    self.name(name, range.start(), write);
                }
                _ => self.element(item, range, None, false),
            }
        }
    }

    /// `GOTOF LABEL1`: the keyword, then the label its target names.
    fn jump(&mut self, node: &GreenNodeData, start: TextSize) {
        for (range, item) in children(node, start) {
            match item {
                NodeOrToken::Node(target) if kind(target.kind()) == SyntaxKind::NAME_REF => {
                    self.tokens(target, range.start(), HighlightKind::Label { write: false });
                }
                _ => self.element(item, range, None, false),
            }
        }
    }

    /// A call by name: a code written as a word (`SOFT`, in its group), a
    /// keyword (`MCALL`), or a command, cycle or subprogram; `L140` and
    /// `M6` with arguments are subprograms.
    fn call(&mut self, node: &GreenNodeData, start: TextSize) {
        for (range, item) in children(node, start) {
            match (kind(item.kind()), item) {
                (SyntaxKind::IDENT, NodeOrToken::Token(token)) => {
                    let highlight = self.called(token.text());
                    self.push(range, highlight, false);
                }
                (SyntaxKind::LETTER | SyntaxKind::NUMBER, _) => self.push(range, HighlightKind::Function, true),
                _ => self.element(item, range, None, false),
            }
        }
    }

    fn called(&mut self, name: &str) -> HighlightKind {
        let catalogue = self.catalogue;
        // A word code's letter is its group's.
        if let Some(letter) = catalogue.word_code(name).and_then(|code| code.group.as_deref()?.bytes().next()) {
            let group = catalogue.word_modal_group_index(name).and_then(|index| u8::try_from(index).ok());
            return HighlightKind::Code { letter, group };
        }
        if catalogue.word_code(name).is_some() || catalogue.keyword(name).is_some() {
            return HighlightKind::Keyword;
        }
        HighlightKind::Function
    }

    /// A declared variable or formal parameter: its name (the first name,
    /// or the first after `after`) is assigned; the rest as it is.
    fn declared(&mut self, node: &GreenNodeData, start: TextSize, after: Option<SyntaxKind>) {
        let mut waiting = after.is_some();
        let mut named = false;
        for (range, item) in children(node, start) {
            let item_kind = kind(item.kind());
            match item {
                NodeOrToken::Token(_)
                    if !waiting && !named && matches!(item_kind, SyntaxKind::IDENT | SyntaxKind::LETTER) =>
                {
                    named = true;
                    self.push(range, HighlightKind::Parameter { write: true }, false);
                }
                _ => {
                    waiting &= Some(item_kind) != after;
                    self.element(item, range, None, false);
                }
            }
        }
    }

    /// `PROC NAME(…)`, `EXTERN NAME(…)`, `DEFINE NAME AS …`: the keyword,
    /// the name, then the parameters and attributes, or the macro's text,
    /// whose letters are addresses.
    fn procedure(&mut self, node: &GreenNodeData, start: TextSize) {
        let mut idents = 0;
        for (range, item) in children(node, start) {
            match (kind(item.kind()), item) {
                (SyntaxKind::IDENT, _) => {
                    idents += 1;
                    let highlight = if idents == 2 { HighlightKind::Function } else { HighlightKind::Keyword };
                    self.push(range, highlight, false);
                }
                (SyntaxKind::LETTER, NodeOrToken::Token(letter)) => {
                    let highlight = letter_kind(self.catalogue, letter.text().as_bytes()[0], None);
                    self.push(range, highlight, false);
                }
                _ => self.element(item, range, None, false),
            }
        }
    }

    /// An operation or a function call: its operator symbols and brackets
    /// are operators, a function's name a keyword.
    fn operation(&mut self, node: &GreenNodeData, start: TextSize) {
        let call = kind(node.kind()) == SyntaxKind::CALL_EXPR;
        for (range, item) in children(node, start) {
            match (kind(item.kind()), item) {
                (SyntaxKind::WHITESPACE, _) => {}
                (_, NodeOrToken::Node(_)) => self.element(item, range, None, false),
                (SyntaxKind::IDENT, _) if call => self.push(range, HighlightKind::Keyword, false),
                _ => self.push(range, HighlightKind::Operator, false),
            }
        }
    }

    /// The catalogue group of code `letter` `number`, as an index.
    fn group(&mut self, letter: u8, number: u32) -> Option<u8> {
        let catalogue = self.catalogue;
        *self.groups.entry((letter, number)).or_insert_with(|| {
            let group = catalogue.group_of(char::from(letter), number)?;
            catalogue.groups.iter().position(|g| std::ptr::eq(g, group)).and_then(|i| u8::try_from(i).ok())
        })
    }

    /// Text that may span lines, one range per line without the blanks
    /// around it.
    fn lines(&mut self, range: TextRange, text: &str) {
        let mut offset = 0;
        for line in text.split_inclusive(['\n', '\r']) {
            let trimmed = line.trim_start();
            let start = offset + line.len() - trimmed.len();
            let content = trimmed.trim_end();
            offset += line.len();
            if content.is_empty() {
                continue;
            }
            let range = TextRange::at(range.start() + TextSize::of(&text[..start]), TextSize::of(content));
            if self.in_prelude && self.keyword_in_prelude {
                self.with_keywords(range, content);
            } else {
                self.push(range, HighlightKind::Comment, false);
            }
        }
    }

    /// A comment of a fixed-cycle file's prelude, with its `$PC` as a keyword.
    fn with_keywords(&mut self, range: TextRange, text: &str) {
        const KEYWORD: &str = "$PC";
        let at = |offset: usize| range.start() + TextSize::of(&text[..offset]);
        let comment = |walk: &mut Walk, piece: std::ops::Range<usize>| {
            let trimmed = text[piece.clone()].trim_start_matches([' ', '\t']);
            let start = piece.end - trimmed.len();
            let end = start + trimmed.trim_end_matches([' ', '\t']).len();
            if end > start {
                walk.push(TextRange::new(at(start), at(end)), HighlightKind::Comment, false);
            }
        };
        let mut done = 0;
        for (found, _) in text.match_indices(KEYWORD) {
            comment(self, done..found);
            self.push(TextRange::at(at(found), TextSize::of(KEYWORD)), HighlightKind::Keyword, false);
            done = found + KEYWORD.len();
        }
        comment(self, done..text.len());
    }
}

/// The kind of a token by itself; `None` for whitespace.
fn token_kind_of(token: SyntaxKind) -> Option<HighlightKind> {
    Some(match token {
        SyntaxKind::WHITESPACE | SyntaxKind::NEWLINE => return None,
        SyntaxKind::COMMENT | SyntaxKind::PREAMBLE | SyntaxKind::TRAILER | SyntaxKind::UNREAD => HighlightKind::Comment,
        SyntaxKind::NUMBER | SyntaxKind::PLUS | SyntaxKind::MINUS => HighlightKind::Number,
        SyntaxKind::PERCENT | SyntaxKind::STAR | SyntaxKind::SLASH => HighlightKind::Keyword,
        SyntaxKind::EQ
        | SyntaxKind::L_BRACK
        | SyntaxKind::R_BRACK
        | SyntaxKind::COMMA
        | SyntaxKind::L_PAREN
        | SyntaxKind::R_PAREN
        | SyntaxKind::COLON
        | SyntaxKind::EQ_EQ
        | SyntaxKind::NEQ
        | SyntaxKind::LT
        | SyntaxKind::LT_EQ
        | SyntaxKind::GT
        | SyntaxKind::GT_EQ
        | SyntaxKind::CONCAT => HighlightKind::Operator,
        SyntaxKind::STRING => HighlightKind::String,
        // `GOTO`, `WHILE`, `DO1`, `END1`.
        SyntaxKind::IDENT => HighlightKind::Keyword,
        // Letters outside words occur only in error nodes.
        _ => HighlightKind::Error,
    })
}

/// The number of a G or M word written as a plain integer (`01`, not `1.`,
/// `-1` or `R1`).
fn code_number(word: &GreenNodeData) -> Option<u32> {
    let value = word.children().skip(1).find(|item| kind(item.kind()) != SyntaxKind::WHITESPACE)?;
    match value {
        NodeOrToken::Token(number) if kind(number.kind()) == SyntaxKind::NUMBER => number.text().parse().ok(),
        _ => None,
    }
}

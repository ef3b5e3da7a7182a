//! The Haas lathe parser.
//!
//! File layout (lathe manual §5.1 (001:366-380)):
//!
//! ```text
//! {blank line} [% line] {block} [% {anything}]
//! ```
//!
//! * A block is one line, with its line break. The program number line
//!   `O1234 (NAME)` is a block too, whose first item is a
//!   `PROGRAM_NUMBER`: a file may hold several programs, and one line kind
//!   keeps every edit inside a block.
//! * A `%` line is a tape mark: the first non-blank line may be one (the
//!   opening mark), and the next line that starts with `%` ends the program;
//!   the control never reads what follows it.
//! * Comments `( … )` and `; …` never span lines, so every line start is a
//!   block start: the incremental reparse relies on that.
//! * Macro statements (`#1 = …`, `IF`, `GOTO`, `WHILE … DO1`, `END1`) are
//!   items of their block; loops are matched later, not here, so an edit
//!   inside a loop reparses one block.

use std::{
    ops::{Deref, DerefMut, Range},
    sync::OnceLock,
};

use rowan::{GreenNode, NodeOrToken};

use super::lexer;
use crate::{
    SyntaxError, SyntaxErrorKind as E,
    SyntaxKind::{self, *},
    encoding::BYTE_ORDER_MARK,
    error::Errors,
    expr::{self, Ahead, Arguments, ExprInput, Grammar},
    green::{self, GreenElement},
    lexing::{Token, range},
    limit::Omitted,
    line_blocks,
    line_cursor::{Lexer, LineCursor, LineParser, TokenError},
    visible,
};

/// The operators of Haas macro expressions, with the Fanuc precedence:
/// `* / MOD AND` bind tighter than `+ - OR XOR`, which bind tighter than the
/// comparisons; all are left-associative.
fn binary(kind: SyntaxKind, text: &str) -> Option<(u8, u8)> {
    match (kind, text) {
        (IDENT, "EQ" | "NE" | "GT" | "GE" | "LT" | "LE") => Some((1, 2)),
        (PLUS | MINUS, _) | (IDENT, "OR" | "XOR") => Some((3, 4)),
        (STAR | SLASH, _) | (IDENT, "MOD" | "AND") => Some((5, 6)),
        _ => None,
    }
}

/// Functions are the catalogue's named operations that are not binary
/// operators; `ATAN` also takes the Fanuc form `ATAN[y]/[x]`.
fn function(name: &str) -> Option<Arguments> {
    static FUNCTIONS: OnceLock<Vec<String>> = OnceLock::new();
    let functions = FUNCTIONS.get_or_init(|| {
        let operations = &ncc_catalog::Dialect::HaasLathe.catalogue().operations;
        operations
            .iter()
            .filter_map(|operation| operation.symbol.clone())
            .filter(|symbol| symbol.bytes().all(|b| b.is_ascii_uppercase()) && binary(IDENT, symbol).is_none())
            .collect()
    });
    match name {
        "ATAN" => Some(Arguments::OneOrSlashPair),
        _ if functions.iter().any(|f| f == name) => Some(Arguments::One),
        _ => None,
    }
}

const GRAMMAR: Grammar = Grammar { binary, function };

pub(crate) fn parse_source_file(text: &str) -> (GreenNode, Vec<SyntaxError>, Vec<Omitted<E>>) {
    parse_source_file_with(text, line_blocks::PARALLEL_THRESHOLD)
}

fn parse_source_file_with(text: &str, parallel_threshold: usize) -> (GreenNode, Vec<SyntaxError>, Vec<Omitted<E>>) {
    let mut children: Vec<GreenElement> = Vec::new();
    let mut errors = Errors::default();
    let mut pos = 0;
    if text.starts_with(BYTE_ORDER_MARK) {
        pos = BYTE_ORDER_MARK.len_utf8();
        children.push(NodeOrToken::Token(rowan::GreenToken::new(ERROR_TOKEN.into(), &text[..pos])));
        errors.kept.push(SyntaxError::new(
            E::ByteOrderMark,
            range(0..pos),
            "the file starts with a byte-order mark: it was saved as Unicode text, but the control reads plain text; save it as plain text",
        ));
    }
    let Layout { opening, body } = layout(text, pos);
    if let Some(mark) = opening {
        let mut parser = Parser::new(text, pos, mark);
        while parser.pos < mark {
            children.push(parser.bump());
        }
        parser.move_to(mark, body.start);
        children.push(NodeOrToken::Node(parser.opening_mark()));
        errors.append(parser.take_errors());
    }
    let (runs, block_errors) = line_blocks::parse_in_parts::<Parser<'_>>(text, body.clone(), parallel_threshold);
    children.extend(runs);
    errors.append(block_errors);
    if body.end < text.len() {
        children.push(NodeOrToken::Node(closing_mark(text, body.end)));
    }
    let (errors, omitted) = errors.finish(text);
    (green::node(SOURCE_FILE, children), errors, omitted)
}

/// Where the tape marks are.
pub(crate) struct Layout {
    /// The opening `%` line's start.
    pub(crate) opening: Option<usize>,
    /// The blocks: from after the opening mark's line to the closing mark
    /// (its line's start) or the end.
    pub(crate) body: Range<usize>,
}

pub(crate) fn layout(text: &str, from: usize) -> Layout {
    let bytes = text.as_bytes();
    let mut opening = None;
    let mut body_start = from;
    let mut at = from;
    while at < text.len() {
        let first = at + bytes[at..].iter().take_while(|b| matches!(b, b' ' | b'\t')).count();
        match bytes.get(first) {
            Some(b'\n' | b'\r') => at = next_line(text, first),
            Some(b'%') => {
                opening = Some(at);
                body_start = next_line(text, first);
                break;
            }
            _ => break,
        }
    }
    let body_end = closing_mark_at(text, body_start).unwrap_or(text.len());
    Layout { opening, body: body_start..body_end }
}

/// The start of the first line at or after `from` (a line start) whose
/// first character other than spaces is `%`.
fn closing_mark_at(text: &str, from: usize) -> Option<usize> {
    let bytes = text.as_bytes();
    let mut search = from;
    while let Some(i) = memchr::memchr(b'%', &bytes[search..]) {
        let percent = search + i;
        let line = crate::lexing::line_start(text, percent).max(from);
        if bytes[line..percent].iter().all(|b| matches!(b, b' ' | b'\t')) {
            return Some(line);
        }
        search = percent + 1;
    }
    None
}

fn next_line(text: &str, at: usize) -> usize {
    crate::limit::next_line_start(text.as_bytes(), at).unwrap_or(text.len())
}

/// The closing tape mark at `at` (its line's start): spaces, `%` and
/// everything after it, which the control never reads.
fn closing_mark(text: &str, at: usize) -> GreenNode {
    let percent = at + text[at..].find('%').expect("a closing mark has its `%`");
    let mut children = Vec::new();
    if percent > at {
        children.push(NodeOrToken::Token(rowan::GreenToken::new(WHITESPACE.into(), &text[at..percent])));
    }
    children.push(NodeOrToken::Token(rowan::GreenToken::new(PERCENT.into(), "%")));
    if percent + 1 < text.len() {
        children.push(NodeOrToken::Token(rowan::GreenToken::new(TRAILER.into(), &text[percent + 1..])));
    }
    green::node(TAPE_MARK, children)
}

pub(super) struct Parser<'a> {
    cursor: LineCursor<'a, HaasLexer>,
}

impl<'a> Deref for Parser<'a> {
    type Target = LineCursor<'a, HaasLexer>;

    fn deref(&self) -> &Self::Target {
        &self.cursor
    }
}

impl DerefMut for Parser<'_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.cursor
    }
}

/// The Haas lathe's tokens; a `(` comment not closed on its line is an
/// error.
pub(super) struct HaasLexer;

impl Lexer for HaasLexer {
    fn token_at(text: &str, pos: usize) -> Token {
        lexer::token_at(text, pos)
    }

    fn unclosed(kind: SyntaxKind, text: &str) -> Option<TokenError> {
        (kind == COMMENT && text.starts_with('(') && !text.ends_with(')')).then(|| {
            let message = "comment `(` not closed by `)` on its line; the rest of the line is read as comment";
            (E::UnclosedComment, 1, message.to_owned())
        })
    }
}

impl<'a> LineParser<'a> for Parser<'a> {
    type Lexer = HaasLexer;

    fn new(text: &'a str, pos: usize, region_end: usize) -> Self {
        Parser { cursor: LineCursor::new(text, pos, region_end) }
    }

    /// One line.
    fn block(&mut self) -> GreenNode {
        let mut children = self.take_block_children();
        let mut started = false;
        loop {
            // Fast paths for what CAM output is made of; each builds exactly
            // the tree the general path below would.
            if let Some(trivia) = self.plain_trivia() {
                let newline = trivia.kind() == NEWLINE.into();
                children.push(trivia);
                if newline {
                    break;
                }
                continue;
            }
            if let Some(word) = self.plain_word() {
                started = true;
                children.push(word);
                continue;
            }
            let Some(token) = self.peek() else { break };
            let child = match token.kind {
                NEWLINE => {
                    children.push(self.bump());
                    break;
                }
                WHITESPACE | COMMENT | UNREAD => {
                    children.push(self.bump());
                    continue;
                }
                SLASH if !started => self.block_skip(),
                LETTER if self.foreign_text_len() > 0 => self.foreign_text(),
                LETTER if self.byte_at(self.pos).eq_ignore_ascii_case(&b'O') => self.program_number(),
                LETTER => self.word(Vec::new()),
                COMMA => self.corner_word(),
                HASH => self.assignment(),
                IDENT => self.statement(),
                NUMBER => match expr::placeholder(&self.text[self.pos..self.pos + token.len]) {
                    Some(message) => self.error_node(E::TemplatePlaceholder, message),
                    None => self.error_node(E::NumberWithoutAddress, "a number must follow an address letter: `X10.`"),
                },
                PLUS | MINUS => self.error_node(E::SignWithoutAddress, "a sign must follow an address letter: `X-10.`"),
                EQ => self.error_node(E::MisplacedEquals, "`=` assigns to a variable only: `#1 = 5.`"),
                PERCENT => self.error_node(E::MisplacedPercent, "a tape mark `%` must be alone on its line"),
                _ => {
                    let shown = visible::quoted(&self.text[self.pos..self.pos + token.len]);
                    self.error_node(E::UnexpectedCharacter, format!("`{shown}` is not allowed here"))
                }
            };
            started = true;
            children.push(child);
        }
        self.block_node(children)
    }
}

impl<'a> Parser<'a> {
    fn byte_at(&self, pos: usize) -> u8 {
        self.text.as_bytes()[pos]
    }

    /// Bumps whitespace into `children`.
    fn bump_whitespace(&mut self, children: &mut Vec<GreenElement>) {
        while self.kind_at(self.pos) == Some(WHITESPACE) {
            children.push(self.bump());
        }
    }

    /// The opening `%` line: spaces, `%`, comments; other text on it is an
    /// error.
    fn opening_mark(&mut self) -> GreenNode {
        let mut children = Vec::new();
        while let Some(token) = self.peek() {
            let child = match token.kind {
                WHITESPACE | COMMENT | NEWLINE | PERCENT | UNREAD => self.bump(),
                _ => self.error_node(E::UnexpectedCharacter, "only a comment may follow the tape mark `%` on its line"),
            };
            children.push(child);
        }
        green::node(TAPE_MARK, children)
    }

    /// An address word such as `X-12.5` or `G01`, read without lexing: what
    /// `word` makes of it. Not `O`, which starts a program number.
    fn plain_word(&mut self) -> Option<GreenElement> {
        match self.text.as_bytes()[..self.end].get(self.pos)? {
            b'O' => None,
            _ => self.cursor.simple_word(b"."),
        }
    }

    /// `/`, and a digit 1 to 9 directly after it.
    fn block_skip(&mut self) -> GreenElement {
        let mut children = vec![self.bump()];
        if let Some(Token { kind: NUMBER, len: 1 }) = self.peek()
            && (b'1'..=b'9').contains(&self.byte_at(self.pos))
        {
            children.push(self.bump());
        }
        NodeOrToken::Node(green::node(BLOCK_SKIP, children))
    }

    fn address_letter(&mut self) -> GreenElement {
        let at = self.pos;
        let letter = self.byte_at(at);
        if letter.is_ascii_lowercase() {
            self.report(
                E::LowercaseAddress,
                at..at + 1,
                format!(
                    "lower-case address `{}`; the control's addresses are upper-case `{}`",
                    letter as char,
                    letter.to_ascii_uppercase() as char
                ),
            );
        }
        self.bump()
    }

    /// `O` and the program number.
    fn program_number(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.address_letter()];
        let number_at = self.skip_whitespace(self.pos);
        if self.kind_at(number_at) == Some(NUMBER) {
            self.space_in_word(start + 1..number_at);
            self.bump_whitespace(&mut children);
            expr::number(self, &mut children);
        } else {
            self.report(E::MissingProgramNumber, start..start + 1, "program number missing after `O`: `O1234`");
        }
        NodeOrToken::Node(green::node(PROGRAM_NUMBER, children))
    }

    fn space_in_word(&mut self, space: Range<usize>) {
        if !space.is_empty() {
            self.report(
                E::SpaceInWord,
                space,
                "space inside a word; write the value right after its address or sign (`Z-30.`)",
            );
        }
    }

    /// `,C1.` / `,R2.`: a corner word.
    fn corner_word(&mut self) -> GreenElement {
        if self.kind_at(self.pos + 1) == Some(LETTER) {
            let comma = self.bump();
            return self.word(vec![comma]);
        }
        self.error_node(E::UnexpectedCharacter, "`,` must be followed by a corner word: `,C1.` or `,R1.`")
    }

    /// A word: address letter, value (after `children`, the comma of a
    /// corner word).
    fn word(&mut self, mut children: Vec<GreenElement>) -> GreenElement {
        if children.is_empty()
            && let Some(word) = self.cursor.simple_word(b".")
        {
            return word;
        }
        let start = self.pos;
        children.push(self.address_letter());
        let value_at = self.skip_whitespace(self.pos);
        if matches!(self.kind_at(value_at), Some(PLUS | MINUS | NUMBER | HASH | L_BRACK)) {
            self.space_in_word(self.pos..value_at);
            self.bump_whitespace(&mut children);
            self.value(&mut children);
        } else {
            let address = &self.text[start..start + 1];
            let message = format!("address `{address}` has no value; write a number (`{address}0` for zero)");
            self.report(E::MissingValue, start..start + 1, message);
        }
        NodeOrToken::Node(green::node(WORD, children))
    }

    /// Length of foreign text at the current position: three or more
    /// letters without a value (`roughing pass`), which is not a keyword.
    fn foreign_text_len(&self) -> usize {
        let value_at = |pos: usize| {
            matches!(self.kind_at(self.skip_whitespace(pos)), Some(PLUS | MINUS | NUMBER | HASH | L_BRACK))
        };
        crate::lexing::foreign_text_len(
            &self.text.as_bytes()[self.pos..self.end],
            |_| false,
            |run| value_at(self.pos + run),
        )
    }

    /// Foreign text, reported once: on the control it is an alarm, in a
    /// program it belongs in a comment.
    fn foreign_text(&mut self) -> GreenElement {
        let start = self.pos;
        let len = self.foreign_text_len();
        let text = &self.text[start..start + len];
        self.pos += len;
        let message = format!(
            "unexpected text `{}`: an address letter must be followed by its value; text belongs in a comment `( … )`",
            visible::quoted(text)
        );
        self.report_from(E::UnexpectedCharacter, start, message);
        NodeOrToken::Node(green::node(ERROR, [NodeOrToken::Token(rowan::GreenToken::new(ERROR_TOKEN.into(), text))]))
    }

    /// `[sign [spaces]] (number | variable | bracket)` into `children`.
    fn value(&mut self, children: &mut Vec<GreenElement>) {
        if let Some(PLUS | MINUS) = self.kind_at(self.pos) {
            let sign_start = self.pos;
            children.push(self.bump());
            let value_at = self.skip_whitespace(self.pos);
            if !matches!(self.kind_at(value_at), Some(NUMBER | HASH | L_BRACK)) {
                self.report_from(E::MissingValue, sign_start, "sign without a value after it");
                return;
            }
            self.space_in_word(self.pos..value_at);
            self.bump_whitespace(children);
        }
        match self.kind_at(self.pos) {
            Some(NUMBER) => expr::number(self, children),
            Some(HASH) => children.push(expr::var_ref(self, &GRAMMAR, 0)),
            Some(L_BRACK) => children.push(expr::bracket(self, &GRAMMAR, 0)),
            _ => unreachable!("value() without a value"),
        }
    }

    /// `#1 = expr`, `#[#2] = expr`.
    fn assignment(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![expr::var_ref(self, &GRAMMAR, 0)];
        match self.significant_at(self.pos) {
            Some(Ahead { kind: EQ, .. }) => {
                self.bump_trivia(&mut children);
                children.push(self.bump());
                self.bump_trivia(&mut children);
                if let Some(value) = expr::expr(self, &GRAMMAR, "a value after `=`") {
                    children.push(value);
                }
            }
            _ => {
                let shown = visible::quoted(&self.text[start..self.pos]);
                self.report_from(
                    E::MalformedStatement,
                    start,
                    format!("`{shown}` on its own does nothing: assign it a value, `{shown} = 1.`"),
                );
            }
        }
        NodeOrToken::Node(green::node(ASSIGN, children))
    }

    fn ident_text(&self) -> &'a str {
        let len = self.peek().map_or(0, |t| t.len);
        &self.text[self.pos..self.pos + len]
    }

    /// A statement that starts with a keyword.
    fn statement(&mut self) -> GreenElement {
        match self.ident_text() {
            "IF" => self.if_statement(),
            "GOTO" => self.goto_statement(),
            "WHILE" | "DO" => self.loop_start(),
            "END" => self.loop_end(),
            keyword => {
                let message = format!("`{keyword}` cannot start a statement");
                self.error_node(E::MalformedStatement, message)
            }
        }
    }

    /// Reports `message` at the keyword that starts at `start`.
    fn malformed(&mut self, start: usize, keyword_len: usize, message: &str) {
        self.report(E::MalformedStatement, start..start + keyword_len, message);
    }

    /// `IF [cond] GOTO n` or `IF [cond] THEN statement`.
    fn if_statement(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        if !self.bracketed_condition(&mut children) {
            self.malformed(start, 2, "`IF` needs its condition in brackets: `IF [#1 GT 0] GOTO 10`");
            return NodeOrToken::Node(green::node(IF_STMT, children));
        }
        let then = self.significant_at(self.pos).filter(|next| next.kind == IDENT);
        match then.map(|next| &self.text[next.range.0..next.range.1]) {
            Some("GOTO") => {
                self.bump_trivia(&mut children);
                children.push(self.goto_statement());
            }
            Some("THEN") => {
                self.bump_trivia(&mut children);
                let then_start = self.pos;
                children.push(self.bump());
                match self.significant_at(self.pos) {
                    Some(Ahead { kind: HASH, .. }) => {
                        self.bump_trivia(&mut children);
                        children.push(self.assignment());
                    }
                    _ => self.malformed(then_start, 4, "`THEN` must be followed by an assignment: `THEN #1 = 0`"),
                }
            }
            _ => self.malformed(start, 2, "`IF [condition]` must be followed by `GOTO n` or `THEN #var = value`"),
        }
        NodeOrToken::Node(green::node(IF_STMT, children))
    }

    /// Spaces and a bracket into `children`, if a bracket follows.
    fn bracketed_condition(&mut self, children: &mut Vec<GreenElement>) -> bool {
        if self.significant_at(self.pos).is_some_and(|next| next.kind == L_BRACK) {
            self.bump_trivia(children);
            children.push(expr::bracket(self, &GRAMMAR, 0));
            true
        } else {
            false
        }
    }

    /// `GOTO` and the target block number (a value).
    fn goto_statement(&mut self) -> GreenElement {
        let mut children = vec![self.bump()];
        self.bump_trivia(&mut children);
        if let Some(target) = expr::atom(self, &GRAMMAR, "the block number to jump to after `GOTO`") {
            children.push(target);
        }
        NodeOrToken::Node(green::node(GOTO_STMT, children))
    }

    /// `WHILE [cond] DOn`, or `DOn` alone.
    fn loop_start(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = Vec::new();
        if self.ident_text() == "WHILE" {
            children.push(self.bump());
            if !self.bracketed_condition(&mut children) {
                self.malformed(start, 5, "`WHILE` needs its condition in brackets: `WHILE [#1 LT 10] DO1`");
                return NodeOrToken::Node(green::node(LOOP_START, children));
            }
            let do_follows = self
                .significant_at(self.pos)
                .is_some_and(|next| next.kind == IDENT && &self.text[next.range.0..next.range.1] == "DO");
            if !do_follows {
                self.malformed(start, 5, "`WHILE [condition]` must be followed by `DO` and the loop number: `DO1`");
                return NodeOrToken::Node(green::node(LOOP_START, children));
            }
            self.bump_trivia(&mut children);
        }
        self.loop_number(&mut children, "`DO` must be followed by the loop number 1, 2 or 3: `DO1`");
        NodeOrToken::Node(green::node(LOOP_START, children))
    }

    /// `ENDn`.
    fn loop_end(&mut self) -> GreenElement {
        let mut children = Vec::new();
        self.loop_number(&mut children, "`END` must be followed by the loop number 1, 2 or 3: `END1`");
        NodeOrToken::Node(green::node(LOOP_END, children))
    }

    /// The keyword and the loop number after it (spaces allowed).
    fn loop_number(&mut self, children: &mut Vec<GreenElement>, missing: &str) {
        let start = self.pos;
        children.push(self.bump());
        let keyword_len = self.pos - start;
        match self.significant_at(self.pos) {
            Some(Ahead { kind: NUMBER, .. }) => {
                self.bump_trivia(children);
                expr::number(self, children);
            }
            _ => self.malformed(start, keyword_len, missing),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::parse_source_file_with;

    /// Parsing in parts gives the tree and the errors of one pass.
    #[test]
    fn parts_parse_like_one_pass() {
        let pieces = [
            "G01 X[#1 + 2.] Z-#2 F0.1 (CUT)\n",
            "IF [#1 GT 2] GOTO 20\r\n",
            "N20 G71 P10 Q20 U0.4 W0.1 D2. ,C1. X12.5. Z\n",
            "WHILE [#1 LT 3] DO1 ; loop\n",
            "( unclosed comment\n",
            // More doubled points on a line than a report keeps.
            &"X1.2. ".repeat(20),
            "\n",
            &"X1. Z2. ".repeat(200),
            "\n",
        ];
        let mut text = String::from("%\nO1 (PARTS)\n");
        for i in 0..3000 {
            text.push_str(pieces[i % pieces.len()]);
        }
        text.push_str("M30\n%\nafter the mark\n");
        let sequential = parse_source_file_with(&text, usize::MAX);
        assert!(!sequential.1.is_empty() && !sequential.2.is_empty(), "errors kept and left out");
        let parallel = parse_source_file_with(&text, 0);
        assert_eq!(sequential, parallel);
        assert_eq!(rowan::SyntaxNode::<crate::NcLanguage>::new_root(parallel.0).to_string(), text);
    }
}

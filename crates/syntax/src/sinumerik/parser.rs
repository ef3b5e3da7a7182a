//! The Sinumerik parser. The grammar is in the module documentation
//! (`sinumerik/mod.rs`).

use std::ops::{Deref, DerefMut, Range};

use rowan::{GreenNode, NodeOrToken};

use super::lexer;
use crate::{
    SyntaxError, SyntaxErrorKind as E,
    SyntaxKind::{self, *},
    encoding::BYTE_ORDER_MARK,
    error::Errors,
    expr::{self, Ahead, ExprInput, MAX_DEPTH},
    green::{self, GreenElement},
    lexing::{Token, range},
    limit::Omitted,
    line_blocks,
    line_cursor::{Lexer, LineCursor, LineParser, TokenError},
    visible,
};

/// The types of definitions and formal parameters (004:1484, 1676, 4915;
/// FRAME: the brief's list).
const TYPES: [&str; 7] = ["INT", "REAL", "BOOL", "CHAR", "STRING", "AXIS", "FRAME"];

/// Words that may stand between `DEF` and the type: the scope of a global
/// definition. Assumption: the seed defines its global data elsewhere
/// (004:1421-1423); these are the data-module forms of the Siemens manual.
const DEF_SCOPES: [&str; 2] = ["NCK", "CHAN"];

/// The jumps (digest §2.5); `GOTOS` (back to the program start) takes no
/// target.
const JUMPS: [&str; 5] = ["GOTO", "GOTOF", "GOTOB", "GOTOC", "GOTOS"];

/// Keywords that only continue another statement.
const CONTINUATIONS: [&str; 5] = ["TO", "OF", "DEFAULT", "AS", "BLOCK"];

/// The left and right binding powers of a binary operator; higher binds
/// tighter and every operator is left-associative. The order is the
/// Siemens priority list of digest §2.4: comparisons, then `<<`, `OR`,
/// `XOR`, `AND`, `B_OR`, `B_XOR`, `B_AND`, `+ -`, `* / DIV MOD`; the frame
/// chaining `:`, which the list does not name, binds tightest
/// (assumption: it joins frames only, so no other operator meets it).
fn binary(kind: SyntaxKind, text: &str) -> Option<(u8, u8)> {
    let word = |name: &str| kind == IDENT && text.eq_ignore_ascii_case(name);
    match kind {
        EQ_EQ | NEQ | LT | LT_EQ | GT | GT_EQ => Some((1, 2)),
        CONCAT => Some((3, 4)),
        PLUS | MINUS => Some((17, 18)),
        STAR | SLASH => Some((19, 20)),
        // Frame chaining: `CTRANS(X,10):CROT(Z,45)`.
        COLON => Some((21, 22)),
        _ if word("OR") => Some((5, 6)),
        _ if word("XOR") => Some((7, 8)),
        _ if word("AND") => Some((9, 10)),
        _ if word("B_OR") => Some((11, 12)),
        _ if word("B_XOR") => Some((13, 14)),
        _ if word("B_AND") => Some((15, 16)),
        _ if word("DIV") || word("MOD") => Some((19, 20)),
        _ => None,
    }
}

/// `NOT` and `B_NOT` bind tighter than every binary operator, like a sign.
const PREFIX_POWER: u8 = 23;

/// A leading `<<` takes what a binary `<<` would take on its right.
const CONVERSION_POWER: u8 = 4;

pub(crate) fn parse_source_file(text: &str) -> (GreenNode, Vec<SyntaxError>, Vec<Omitted<E>>) {
    parse_source_file_with(text, line_blocks::PARALLEL_THRESHOLD)
}

fn parse_source_file_with(text: &str, parallel_threshold: usize) -> (GreenNode, Vec<SyntaxError>, Vec<Omitted<E>>) {
    let mut children: Vec<GreenElement> = Vec::new();
    let mut errors = Errors::default();
    let mut start = 0;
    if text.starts_with(BYTE_ORDER_MARK) {
        start = BYTE_ORDER_MARK.len_utf8();
        children.push(NodeOrToken::Token(rowan::GreenToken::new(ERROR_TOKEN.into(), &text[..start])));
        errors.kept.push(SyntaxError::new(
            E::ByteOrderMark,
            range(0..start),
            "the file starts with a byte-order mark: it was saved as Unicode text, but the control reads plain text; save it as plain text",
        ));
    }
    let (runs, block_errors) = line_blocks::parse_in_parts::<Parser<'_>>(text, start..text.len(), parallel_threshold);
    children.extend(runs);
    errors.append(block_errors);
    let (errors, omitted) = errors.finish(text);
    (green::node(SOURCE_FILE, children), errors, omitted)
}

pub(super) struct Parser<'a> {
    cursor: LineCursor<'a, SinumerikLexer>,
}

impl<'a> Deref for Parser<'a> {
    type Target = LineCursor<'a, SinumerikLexer>;

    fn deref(&self) -> &Self::Target {
        &self.cursor
    }
}

impl DerefMut for Parser<'_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.cursor
    }
}

/// Sinumerik's tokens; a string not closed on its line is an error.
pub(super) struct SinumerikLexer;

impl Lexer for SinumerikLexer {
    fn token_at(text: &str, pos: usize) -> Token {
        lexer::token_at(text, pos)
    }

    fn unclosed(kind: SyntaxKind, text: &str) -> Option<TokenError> {
        (kind == STRING && (text.len() < 2 || !text.ends_with(&text[..1]))).then(|| {
            let quote = &text[..1];
            let message = format!("string `{quote}` not closed by `{quote}` on its line; a string cannot span lines");
            (E::UnclosedString, 1, message)
        })
    }
}

impl<'a> LineParser<'a> for Parser<'a> {
    type Lexer = SinumerikLexer;

    fn new(text: &'a str, pos: usize, region_end: usize) -> Self {
        Parser { cursor: LineCursor::new(text, pos, region_end) }
    }

    /// One line: `[/n] [%header | N10 | :10] [LABEL:] statement* [;comment]`.
    fn block(&mut self) -> GreenNode {
        let mut children = self.take_block_children();
        if let Some(number) = self.plain_block_number() {
            children.push(number);
        } else {
            self.trivia(&mut children);
            if self.kind_at(self.pos) == Some(SLASH) {
                children.push(self.block_skip());
                self.trivia(&mut children);
            }
            match self.kind_at(self.pos) {
                Some(PERCENT) => children.push(self.header()),
                Some(COLON) if self.kind_at(self.pos + 1) == Some(NUMBER) => children.push(self.block_number()),
                Some(LETTER)
                    if self.text.as_bytes()[self.pos].eq_ignore_ascii_case(&b'N')
                        && self.kind_at(self.pos + 1) == Some(NUMBER) =>
                {
                    children.push(self.block_number());
                }
                _ => {}
            }
        }
        self.trivia(&mut children);
        if self.kind_at(self.pos) == Some(IDENT) && self.label_follows() {
            children.push(self.label());
        }
        self.statements(&mut children);
        self.block_node(children)
    }
}

impl<'a> Parser<'a> {
    /// The text of the token at `pos`.
    fn text_at(&self, pos: usize) -> &'a str {
        let len = self.token_at(pos).map_or(0, |t| t.len);
        &self.text[pos..pos + len]
    }

    /// Whether the next significant token is the keyword `keyword`.
    fn keyword_ahead(&self, keyword: &str) -> bool {
        self.significant_at(self.pos)
            .is_some_and(|next| next.kind == IDENT && self.text_at(next.range.0).eq_ignore_ascii_case(keyword))
    }

    fn significant_kind(&self) -> Option<SyntaxKind> {
        self.significant_at(self.pos).map(|next| next.kind)
    }

    /// Bumps the next significant token with the trivia before it.
    fn bump_significant(&mut self, children: &mut Vec<GreenElement>) {
        self.trivia(children);
        children.push(self.bump());
    }

    fn node(kind: SyntaxKind, children: Vec<GreenElement>) -> GreenElement {
        NodeOrToken::Node(green::node(kind, children))
    }

    /// Statements up to the end of the line, with its line break.
    fn statements(&mut self, children: &mut Vec<GreenElement>) {
        loop {
            // Fast paths for what CAM output is made of; each builds exactly
            // the tree the general path below would.
            if let Some(trivia) = self.plain_trivia() {
                let newline = trivia.kind() == NEWLINE.into();
                children.push(trivia);
                if newline {
                    return;
                }
                continue;
            }
            if let Some(word) = self.plain_word() {
                children.push(word);
                continue;
            }
            let Some(token) = self.peek() else { return };
            match token.kind {
                NEWLINE => {
                    children.push(self.bump());
                    return;
                }
                WHITESPACE | COMMENT | UNREAD => children.push(self.bump()),
                _ => children.push(self.statement()),
            }
        }
    }

    /// `N` and digits at the line start, the block number of nearly every
    /// block, read without lexing; `None`, reading nothing, for any other
    /// text (a number with a point or an exponent takes the general path).
    fn plain_block_number(&mut self) -> Option<GreenElement> {
        let bytes = &self.text.as_bytes()[..self.end];
        let start = self.pos;
        let letter = *bytes.get(start)?;
        let digits = bytes[start + 1..].iter().take_while(|b| b.is_ascii_digit()).count();
        let plain = letter.eq_ignore_ascii_case(&b'N')
            && digits > 0
            && !matches!(bytes.get(start + 1 + digits), Some(b'.' | b'E' | b'e'));
        if !plain {
            return None;
        }
        self.pos = start + 1 + digits;
        let number = self.green.token(NUMBER, &self.text[start + 1..self.pos]);
        Some(NodeOrToken::Node(green::node(BLOCK_NUMBER, [self.green.letter(letter), number])))
    }

    /// An address word such as `X-12.5` or `G1`, read without lexing: what
    /// `statement` makes of it. Not `R`, which starts a parameter, nor an
    /// `L` or `M` number with arguments (`L140(1)`, a call).
    fn plain_word(&mut self) -> Option<GreenElement> {
        let glued: &[u8] = match self.text.as_bytes()[..self.end].get(self.pos)? {
            b'R' => return None,
            b'L' | b'M' => b".=Ee(",
            _ => b".=Ee",
        };
        self.cursor.simple_word(glued)
    }

    /// `/`, and a level digit directly after it.
    fn block_skip(&mut self) -> GreenElement {
        let mut children = vec![self.bump()];
        if let Some(Token { kind: NUMBER, len: 1 }) = self.peek()
            && self.text.as_bytes()[self.pos].is_ascii_digit()
        {
            children.push(self.bump());
        }
        Self::node(BLOCK_SKIP, children)
    }

    /// `%_N_NAME_MPF`: the header line of a file in an archive or as the
    /// control writes it out.
    fn header(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        match self.kind_at(self.pos) {
            Some(IDENT | NUMBER) => children.push(self.bump()),
            _ => self.report(
                E::MissingProgramNumber,
                start..start + 1,
                "`%` must be followed by the program name: `%_N_PART_MPF`",
            ),
        }
        Self::node(HEADER, children)
    }

    /// `N10` or `:10`.
    fn block_number(&mut self) -> GreenElement {
        let mut children = vec![self.bump()];
        expr::number(self, &mut children);
        Self::node(BLOCK_NUMBER, children)
    }

    fn label_follows(&self) -> bool {
        let name = self.peek().map_or(0, |t| t.len);
        self.kind_at(self.pos + name) == Some(COLON)
    }

    /// `NAME:`.
    fn label(&mut self) -> GreenElement {
        let children = vec![self.bump(), self.bump()];
        Self::node(LABEL, children)
    }

    fn statement(&mut self) -> GreenElement {
        let token = self.peek().expect("a statement at a token");
        match token.kind {
            LETTER => self.letter_statement(),
            IDENT => self.name_statement(),
            NUMBER => match expr::placeholder(self.text_at(self.pos)) {
                Some(message) => self.error_node(E::TemplatePlaceholder, message),
                None => self.error_node(E::NumberWithoutAddress, "a number must follow an address letter: `X10`"),
            },
            PLUS | MINUS => self.error_node(E::SignWithoutAddress, "a sign must follow an address letter: `X-10`"),
            EQ => self.error_node(E::MisplacedEquals, "`=` must follow an address or a variable: `X=R1`, `R1=5`"),
            PERCENT => self.error_node(E::MisplacedPercent, "`%` starts a file header line only: `%_N_PART_MPF`"),
            L_PAREN => self.parenthesis_comment(),
            SLASH => self.error_node(E::UnexpectedCharacter, "block skip `/` must start the block"),
            COLON => self.error_node(
                E::UnexpectedCharacter,
                "`:` follows a label name (`LOOP1:`) or starts a main block number (`:10`) at the start of a block",
            ),
            _ => {
                let shown = visible::quoted(self.text_at(self.pos));
                self.error_node(E::UnexpectedCharacter, format!("`{shown}` is not allowed here"))
            }
        }
    }

    /// `( … )` where a statement must be: a comment in Fanuc style.
    fn parenthesis_comment(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = Vec::new();
        while let Some(token) = self.peek() {
            if matches!(token.kind, NEWLINE | COMMENT | UNREAD) {
                break;
            }
            children.push(self.bump());
            if token.kind == R_PAREN {
                break;
            }
        }
        self.report_from(
            E::ParenthesisComment,
            start,
            "Sinumerik reads `( … )` as code, not as a comment; write comments after `;`",
        );
        Self::node(ERROR, children)
    }

    /// A statement that starts with an address letter: a word (`X10`,
    /// `X=R1+5`, `A3=1`), an R parameter assignment (`R1=5`, `R[R2]=1`) or
    /// an indexed assignment (`G[8]=2`).
    fn letter_statement(&mut self) -> GreenElement {
        let start = self.pos;
        if self.is_parameter_at(start) {
            let target = self.param_ref();
            return self.assignment_to(target, start);
        }
        if self.numbered_call_at(start) {
            let mut children = vec![self.bump(), self.bump()];
            self.trivia(&mut children);
            children.push(self.arg_list(0));
            return Self::node(CALL_STMT, children);
        }
        if self.kind_at(start + 1) == Some(L_BRACK) {
            let name = self.bump();
            let target = self.index_expr(Self::node(NAME_REF, vec![name]), 0);
            return self.assignment_to(target, start);
        }
        self.word()
    }

    /// A numbered subprogram (`L` and digits, the older naming the Siemens
    /// manual keeps) or an M function a subprogram replaces, with arguments
    /// glued to it: `L140(1)`, `M6(T1)` (assumptions, the seed has none).
    /// Without arguments `L140` and `M6` are words, which the lowering
    /// reads as the call.
    fn numbered_call_at(&self, pos: usize) -> bool {
        let Some(Token { kind: NUMBER, len }) = self.token_at(pos + 1) else { return false };
        matches!(self.text.as_bytes()[pos].to_ascii_uppercase(), b'L' | b'M')
            && !self.text_at(pos + 1).contains('.')
            && self.kind_at(pos + 1 + len) == Some(L_PAREN)
    }

    /// `R` directly followed by its number or index.
    fn is_parameter_at(&self, pos: usize) -> bool {
        self.text.as_bytes()[pos].eq_ignore_ascii_case(&b'R') && matches!(self.kind_at(pos + 1), Some(NUMBER | L_BRACK))
    }

    /// `R12`, `R[expr]`.
    fn param_ref(&mut self) -> GreenElement {
        let mut children = vec![self.bump()];
        if self.kind_at(self.pos) == Some(NUMBER) {
            expr::number(self, &mut children);
            return Self::node(PARAM_REF, children);
        }
        self.index(&mut children, 0);
        Self::node(PARAM_REF, children)
    }

    /// `target = expr`; a target on its own is an error.
    fn assignment_to(&mut self, target: GreenElement, start: usize) -> GreenElement {
        let mut children = vec![target];
        if self.significant_kind() == Some(EQ) {
            self.bump_significant(&mut children);
            self.trivia(&mut children);
            if let Some(value) = self.expr("a value after `=`") {
                children.push(value);
            }
            return Self::node(ASSIGN, children);
        }
        let shown = visible::quoted(&self.text[start..self.pos]);
        let kind = if self.is_parameter_at(start) { E::ParameterWithoutAssignment } else { E::MalformedStatement };
        self.report_from(kind, start, format!("`{shown}` on its own does nothing: assign it a value, `{shown}=1`"));
        Self::node(ERROR, children)
    }

    /// An address with its value: `X-12.5`, `G1`, `X=R1+5`, `X = 5`, and an
    /// address with its extension, which takes `=` (`A3=1`, `X1=X`).
    fn word(&mut self) -> GreenElement {
        if let Some(word) = self.cursor.simple_word(b".=Ee") {
            return word;
        }
        let start = self.pos;
        let mut children = vec![self.bump()];
        let extension = self.kind_at(self.pos) == Some(NUMBER)
            && !self.text_at(self.pos).contains('.')
            && self.kind_at(self.pos + self.text_at(self.pos).len()) == Some(EQ);
        if extension {
            children.push(self.bump());
        }
        if self.significant_kind() == Some(EQ) {
            self.bump_significant(&mut children);
            self.trivia(&mut children);
            if let Some(value) = self.expr("a value after `=`") {
                children.push(value);
            }
            return Self::node(WORD, children);
        }
        let value_at = self.skip_whitespace(self.pos);
        if !matches!(self.kind_at(value_at), Some(PLUS | MINUS | NUMBER)) {
            let address = &self.text[start..start + 1];
            let message = format!(
                "address `{address}` has no value: write a number (`{address}0`) or `{address}=` and an expression"
            );
            self.report(E::MissingValue, start..start + 1, message);
            return Self::node(WORD, children);
        }
        self.space_in_word(self.pos..value_at, &mut children);
        if let Some(PLUS | MINUS) = self.kind_at(self.pos) {
            let sign = self.pos;
            children.push(self.bump());
            let number_at = self.skip_whitespace(self.pos);
            if self.kind_at(number_at) != Some(NUMBER) {
                self.report_from(
                    E::MissingValue,
                    sign,
                    "sign without a number after it; an expression needs `=`: `X=-R1`",
                );
                return Self::node(WORD, children);
            }
            self.space_in_word(self.pos..number_at, &mut children);
        }
        expr::number(self, &mut children);
        Self::node(WORD, children)
    }

    fn space_in_word(&mut self, space: Range<usize>, children: &mut Vec<GreenElement>) {
        if !space.is_empty() {
            self.report(
                E::SpaceInWord,
                space.clone(),
                "space inside a word; write the value right after its address or sign (`Z-30`)",
            );
            while self.pos < space.end {
                children.push(self.bump());
            }
        }
    }

    /// A statement that starts with a name: a keyword statement, an
    /// assignment, a misplaced label, or a command or call.
    fn name_statement(&mut self) -> GreenElement {
        let keyword = self.text_at(self.pos).to_ascii_uppercase();
        match keyword.as_str() {
            "IF" => self.if_statement(),
            "ELSE" => Self::node(ELSE_STMT, vec![self.bump()]),
            "ENDIF" => Self::node(ENDIF_STMT, vec![self.bump()]),
            "WHILE" => self.conditional(LOOP_START, "`WHILE` needs a condition: `WHILE R1<10`"),
            "UNTIL" => self.conditional(LOOP_END, "`UNTIL` needs a condition: `UNTIL R1>=10`"),
            "ENDWHILE" | "ENDFOR" | "ENDLOOP" => Self::node(LOOP_END, vec![self.bump()]),
            "LOOP" => Self::node(LOOP_START, vec![self.bump()]),
            // `REPEAT` alone opens a loop; with labels after it, it repeats
            // a program section (`REPEAT MARK P=2`), a command.
            "REPEAT" if self.line_ends_after(self.pos + keyword.len()) => Self::node(LOOP_START, vec![self.bump()]),
            "FOR" => self.for_statement(),
            "CASE" => self.case_statement(),
            _ if JUMPS.contains(&keyword.as_str()) => self.goto_statement(),
            "DEF" => self.def_statement(),
            "PROC" => self.proc_statement(),
            "EXTERN" => self.extern_statement(),
            "WHEN" | "WHENEVER" | "EVERY" | "FROM" => self.sync_action(),
            // A synchronous action without a condition: `IDS=1 DO …`.
            "DO" => self.sync_actions(Vec::new()),
            "MCALL" => self.modal_call(),
            "CALL" => self.indirect_call(),
            "PCALL" => self.path_call(),
            "DEFINE" => self.macro_definition(),
            _ if CONTINUATIONS.contains(&keyword.as_str()) => {
                let message = format!("`{keyword}` continues another statement and cannot start one");
                self.error_node(E::MalformedStatement, message)
            }
            _ => self.named_statement(),
        }
    }

    /// Whether nothing but trivia follows `from` on the line.
    fn line_ends_after(&self, from: usize) -> bool {
        self.significant_at(from).is_none()
    }

    /// An assignment `NAME=…`, `NAME[i]=…`, a label out of place, or a call.
    fn named_statement(&mut self) -> GreenElement {
        let start = self.pos;
        if self.label_follows() {
            let label = self.label();
            self.report_from(E::MalformedStatement, start, "a label must start its block, after the block number");
            return label;
        }
        let name_end = start + self.text_at(start).len();
        match self.significant_at(name_end).map(|next| next.kind) {
            Some(EQ) => {
                let name = Self::node(NAME_REF, vec![self.bump()]);
                self.assignment_to(name, start)
            }
            Some(L_BRACK) => {
                let name = Self::node(NAME_REF, vec![self.bump()]);
                let target = self.index_expr(name, 0);
                self.assignment_to(target, start)
            }
            _ => self.call_statement(),
        }
    }

    /// A name with its arguments, if any: `TRAORI`, `CYCLE81(10,0,2)`,
    /// `MSG ("…")`.
    fn call_statement(&mut self) -> GreenElement {
        let mut children = vec![self.bump()];
        if self.significant_kind() == Some(L_PAREN) {
            self.trivia(&mut children);
            children.push(self.arg_list(0));
        }
        Self::node(CALL_STMT, children)
    }

    /// `MCALL name(args)`, or `MCALL` alone, which ends the modal call.
    fn modal_call(&mut self) -> GreenElement {
        let mut children = vec![self.bump()];
        if self.significant_kind() == Some(IDENT) {
            self.trivia(&mut children);
            children.push(self.call_statement());
        }
        Self::node(CALL_STMT, children)
    }

    /// `IF cond`, or the one-line jump `IF cond GOTOF target`.
    fn if_statement(&mut self) -> GreenElement {
        let mut children = vec![self.bump()];
        self.trivia(&mut children);
        if let Some(condition) = self.expr("a condition after `IF`") {
            children.push(condition);
        }
        let jump = self.significant_at(self.pos).is_some_and(|next| {
            next.kind == IDENT && JUMPS.iter().any(|jump| self.text_at(next.range.0).eq_ignore_ascii_case(jump))
        });
        if jump {
            self.trivia(&mut children);
            children.push(self.goto_statement());
        }
        Self::node(IF_STMT, children)
    }

    /// A keyword and its condition: `WHILE cond`, `UNTIL cond`.
    fn conditional(&mut self, kind: SyntaxKind, missing: &str) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        let keyword_end = self.pos;
        self.trivia(&mut children);
        match self.significant_kind() {
            Some(_) => {
                if let Some(condition) = self.expr("a condition") {
                    children.push(condition);
                }
            }
            None => self.report(E::MalformedStatement, start..keyword_end, missing),
        }
        Self::node(kind, children)
    }

    /// `FOR var = start TO end`.
    fn for_statement(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        let keyword_end = self.pos;
        let missing = "`FOR` needs a variable, its start and its end: `FOR I=1 TO 10`";
        let variable_at = self.significant_at(self.pos).filter(|next| matches!(next.kind, IDENT | LETTER));
        let Some(variable_at) = variable_at else {
            self.report(E::MalformedStatement, start..keyword_end, missing);
            return Self::node(LOOP_START, children);
        };
        self.trivia(&mut children);
        let target = if self.is_parameter_at(variable_at.range.0) {
            self.param_ref()
        } else {
            Self::node(NAME_REF, vec![self.bump()])
        };
        if self.significant_kind() != Some(EQ) {
            self.report(E::MalformedStatement, start..keyword_end, missing);
            children.push(target);
            return Self::node(LOOP_START, children);
        }
        children.push(self.assignment_to(target, variable_at.range.0));
        if self.keyword_ahead("TO") {
            self.bump_significant(&mut children);
            self.trivia(&mut children);
            if let Some(end) = self.expr("the end value after `TO`") {
                children.push(end);
            }
        } else {
            self.report(E::MalformedStatement, start..keyword_end, missing);
        }
        Self::node(LOOP_START, children)
    }

    /// `CASE expr OF const GOTOx target … [DEFAULT GOTOx target]`.
    fn case_statement(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        let keyword_end = self.pos;
        self.trivia(&mut children);
        if let Some(selector) = self.expr("the value to select by after `CASE`") {
            children.push(selector);
        }
        if !self.keyword_ahead("OF") {
            self.report(
                E::MalformedStatement,
                start..keyword_end,
                "`CASE value` must be followed by `OF` and its arms: `CASE R1 OF 1 GOTOF L1`",
            );
            return Self::node(CASE_STMT, children);
        }
        self.bump_significant(&mut children);
        // An arm starts with a constant or `DEFAULT`; anything else ends the
        // CASE and is the block's next statement.
        while let Some(next) = self.significant_at(self.pos).filter(|next| {
            matches!(next.kind, NUMBER | STRING | PLUS | MINUS)
                || (next.kind == IDENT && self.text_at(next.range.0).eq_ignore_ascii_case("DEFAULT"))
        }) {
            let arm_start = next.range.0;
            let mut arm = Vec::new();
            self.trivia(&mut children);
            if self.keyword_ahead("DEFAULT") {
                arm.push(self.bump());
            } else {
                match self.atom("a value of the arm (`1 GOTOF L1`)", 0) {
                    Some(value) => arm.push(value),
                    None => break,
                }
            }
            let jump = self.significant_at(self.pos).is_some_and(|next| {
                next.kind == IDENT && JUMPS.iter().any(|jump| self.text_at(next.range.0).eq_ignore_ascii_case(jump))
            });
            if !jump {
                self.report_from(
                    E::MalformedStatement,
                    arm_start,
                    "a CASE arm must be followed by a jump: `1 GOTOF L1`",
                );
                children.push(Self::node(CASE_ARM, arm));
                break;
            }
            self.trivia(&mut arm);
            arm.push(self.goto_statement());
            children.push(Self::node(CASE_ARM, arm));
        }
        Self::node(CASE_STMT, children)
    }

    /// A jump and its target: a label, a block number `N10`, or a string
    /// expression (`"N"<<R3`); `GOTOS` has none.
    fn goto_statement(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        let keyword = self.text[start..self.pos].to_ascii_uppercase();
        if keyword == "GOTOS" {
            return Self::node(GOTO_STMT, children);
        }
        let target = self.significant_at(self.pos);
        match target {
            Some(Ahead { kind: LETTER, range: (at, _) })
                if self.text.as_bytes()[at].eq_ignore_ascii_case(&b'N') && self.kind_at(at + 1) == Some(NUMBER) =>
            {
                self.trivia(&mut children);
                children.push(self.block_number());
            }
            Some(_) => {
                self.trivia(&mut children);
                if let Some(target) = self.expr("the jump target: a label, a block number `N10` or a string") {
                    children.push(target);
                }
            }
            None => {
                let message =
                    format!("`{keyword}` needs a target: a label, a block number `N10` or a string expression");
                self.report_from(E::MalformedStatement, start, message);
            }
        }
        Self::node(GOTO_STMT, children)
    }

    /// `DEF [NCK|CHAN] type name[dims][=value], …`.
    fn def_statement(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        let keyword_end = self.pos;
        if DEF_SCOPES.iter().any(|scope| self.keyword_ahead(scope)) {
            self.bump_significant(&mut children);
        }
        if !self.type_ahead() {
            let message = format!("`DEF` must be followed by a type ({}) and a name: `DEF REAL X1`", TYPES.join(", "));
            self.report(E::MalformedStatement, start..keyword_end, message);
            return Self::node(DEF_STMT, children);
        }
        self.trivia(&mut children);
        children.push(self.type_ref());
        loop {
            if !self.name_ahead() {
                self.report(
                    E::MalformedStatement,
                    start..keyword_end,
                    "`DEF type` must be followed by the names it defines",
                );
                break;
            }
            self.trivia(&mut children);
            children.push(self.var_decl());
            if self.significant_kind() != Some(COMMA) {
                break;
            }
            self.bump_significant(&mut children);
        }
        Self::node(DEF_STMT, children)
    }

    fn type_ahead(&self) -> bool {
        TYPES.iter().any(|name| self.keyword_ahead(name))
    }

    /// A name a definition or a parameter list declares: a name, or a
    /// letter (the seed's formal parameters `REAL C, REAL X`, 004:1506).
    fn name_ahead(&self) -> bool {
        matches!(self.significant_kind(), Some(IDENT | LETTER)) && !self.type_ahead()
    }

    /// A name being declared into `children`: a name, or a letter with the
    /// digits glued to it (`P1`, the old numbered subprograms `L10`).
    fn declared_name(&mut self, children: &mut Vec<GreenElement>) {
        let letter = self.kind_at(self.pos) == Some(LETTER);
        children.push(self.bump());
        if letter && self.kind_at(self.pos) == Some(NUMBER) && !self.text_at(self.pos).contains('.') {
            children.push(self.bump());
        }
    }

    /// `REAL`, `STRING[20]`.
    fn type_ref(&mut self) -> GreenElement {
        let mut children = vec![self.bump()];
        if self.significant_kind() == Some(L_BRACK) {
            self.trivia(&mut children);
            self.index(&mut children, 0);
        }
        Self::node(TYPE, children)
    }

    /// `NAME[dims] = value`: the name and what follows it.
    fn var_decl(&mut self) -> GreenElement {
        let mut children = Vec::new();
        self.declared_name(&mut children);
        if self.significant_kind() == Some(L_BRACK) {
            self.trivia(&mut children);
            self.index(&mut children, 0);
        }
        if self.significant_kind() == Some(EQ) {
            self.bump_significant(&mut children);
            self.trivia(&mut children);
            if let Some(value) = self.expr("the initial value after `=`") {
                children.push(value);
            }
        }
        Self::node(VAR_DECL, children)
    }

    /// `PROC name (parameters) attributes`: the attributes (`SAVE`,
    /// `DISPLOF`, `SBLOF`, …) are the names after the list.
    fn proc_statement(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        if !matches!(self.significant_kind(), Some(IDENT | LETTER)) {
            self.report_from(
                E::MalformedStatement,
                start,
                "`PROC` must be followed by the program's name: `PROC CONTOUR`",
            );
            return Self::node(PROC_STMT, children);
        }
        self.trivia(&mut children);
        self.declared_name(&mut children);
        if self.significant_kind() == Some(L_PAREN) {
            self.trivia(&mut children);
            self.parameter_list(&mut children);
        }
        while let Some(next) = self.significant_at(self.pos).filter(|next| next.kind == IDENT) {
            // A name with arguments or a value is the block's next statement.
            let after = self.significant_at(next.range.1).map(|after| after.kind);
            if matches!(after, Some(L_PAREN | L_BRACK | EQ | COLON)) {
                break;
            }
            self.bump_significant(&mut children);
        }
        Self::node(PROC_STMT, children)
    }

    /// `EXTERN name (types)`.
    fn extern_statement(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        if !matches!(self.significant_kind(), Some(IDENT | LETTER)) {
            let message = "`EXTERN` must be followed by the subprogram's name and parameter types: `EXTERN CONTOUR(REAL, VAR INT)`";
            self.report_from(E::MalformedStatement, start, message);
            return Self::node(EXTERN_STMT, children);
        }
        self.trivia(&mut children);
        self.declared_name(&mut children);
        if self.significant_kind() == Some(L_PAREN) {
            self.trivia(&mut children);
            self.parameter_list(&mut children);
        }
        Self::node(EXTERN_STMT, children)
    }

    /// `( [VAR] type [name] [dims], … )` into `children`.
    fn parameter_list(&mut self, children: &mut Vec<GreenElement>) {
        let open = self.pos;
        children.push(self.bump());
        loop {
            let param_start = self.significant_at(self.pos).map_or(self.pos, |next| next.range.0);
            let mut param = Vec::new();
            if self.keyword_ahead("VAR") {
                self.bump_significant(&mut param);
            }
            if self.type_ahead() {
                self.trivia(&mut param);
                param.push(self.type_ref());
                if self.name_ahead() {
                    self.trivia(&mut param);
                    self.declared_name(&mut param);
                }
                if self.significant_kind() == Some(L_BRACK) {
                    self.trivia(&mut param);
                    self.index(&mut param, 0);
                }
            } else if self.significant_kind() != Some(R_PAREN) || !param.is_empty() {
                let message =
                    format!("a parameter is a type ({}) and a name: `REAL X1`, `VAR INT N`", TYPES.join(", "));
                let end = self.significant_at(self.pos).map_or(param_start, |next| next.range.1);
                self.report(E::MalformedStatement, param_start..end.max(param_start), message);
            }
            if !param.is_empty() {
                children.push(Self::node(PARAM, param));
            }
            match self.significant_kind() {
                Some(COMMA) => self.bump_significant(children),
                Some(R_PAREN) => {
                    self.bump_significant(children);
                    return;
                }
                _ => {
                    self.close_paren(open, children, true);
                    return;
                }
            }
        }
    }

    /// `WHEN|WHENEVER|EVERY|FROM cond DO actions`: the actions are the rest
    /// of the line.
    fn sync_action(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        let keyword_end = self.pos;
        self.trivia(&mut children);
        if let Some(condition) = self.expr("the condition of the synchronous action") {
            children.push(condition);
        }
        if !self.keyword_ahead("DO") {
            self.report(
                E::MalformedStatement,
                start..keyword_end,
                "a synchronous action needs `DO` and its actions: `WHEN $AA_IM[X]>10 DO M7`",
            );
            return Self::node(SYNC_ACTION, children);
        }
        self.trivia(&mut children);
        self.sync_actions(children)
    }

    /// `DO` and the actions after it, to the end of the line, after
    /// `children` (the condition, if any).
    fn sync_actions(&mut self, mut children: Vec<GreenElement>) -> GreenElement {
        children.push(self.bump());
        while let Some(token) = self.peek() {
            match token.kind {
                NEWLINE => break,
                WHITESPACE | COMMENT | UNREAD => children.push(self.bump()),
                _ => children.push(self.statement()),
            }
        }
        Self::node(SYNC_ACTION, children)
    }

    /// `CALL program [BLOCK start TO end]`: a call by a computed name, or
    /// of a program section (assumption: the Siemens form with `BLOCK`,
    /// digest §8 item 9).
    fn indirect_call(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        let keyword_end = self.pos;
        if self.significant_kind().is_none() {
            self.report(
                E::MalformedStatement,
                start..keyword_end,
                "`CALL` must be followed by the program: `CALL \"/_N_SPF_DIR/_N_SUB_SPF\"`",
            );
            return Self::node(CALL_STMT, children);
        }
        self.trivia(&mut children);
        if let Some(program) = self.expr("the program to call") {
            children.push(program);
        }
        if self.keyword_ahead("BLOCK") {
            self.bump_significant(&mut children);
            self.trivia(&mut children);
            if let Some(from) = self.expr("the label the section starts at") {
                children.push(from);
            }
            if self.keyword_ahead("TO") {
                self.bump_significant(&mut children);
                self.trivia(&mut children);
                if let Some(to) = self.expr("the label the section ends at") {
                    children.push(to);
                }
            }
        }
        Self::node(CALL_STMT, children)
    }

    /// `PCALL path(args)`: a call of a program by its path written out,
    /// `PCALL /_N_CST_DIR/_N_SUB_SPF(1,2)` (assumption: the Siemens form,
    /// the seed has none); the path is its `/` and name tokens.
    fn path_call(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        let keyword_end = self.pos;
        let path_at = self.skip_whitespace(self.pos);
        if !matches!(self.kind_at(path_at), Some(SLASH | IDENT)) {
            self.report(
                E::MalformedStatement,
                start..keyword_end,
                "`PCALL` must be followed by the program's path: `PCALL /_N_SPF_DIR/_N_SUB_SPF`",
            );
            return Self::node(CALL_STMT, children);
        }
        self.trivia(&mut children);
        while let Some(SLASH | IDENT) = self.kind_at(self.pos) {
            children.push(self.bump());
        }
        if self.significant_kind() == Some(L_PAREN) {
            self.trivia(&mut children);
            children.push(self.arg_list(0));
        }
        Self::node(CALL_STMT, children)
    }

    /// `DEFINE name AS text`: a macro, whose text (the rest of the line)
    /// the lowering substitutes; it is kept as tokens, not parsed.
    fn macro_definition(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = vec![self.bump()];
        let keyword_end = self.pos;
        let name = self.significant_kind().is_some_and(|kind| matches!(kind, IDENT | LETTER));
        let as_at =
            name.then(|| self.significant_at(self.pos)).flatten().and_then(|name| self.significant_at(name.range.1));
        let has_as =
            as_at.is_some_and(|next| next.kind == IDENT && self.text_at(next.range.0).eq_ignore_ascii_case("AS"));
        if !has_as {
            self.report(
                E::MalformedStatement,
                start..keyword_end,
                "`DEFINE` must be followed by a name, `AS` and its text: `DEFINE COOLANT_ON AS M8`",
            );
            return Self::node(MACRO_DEF, children);
        }
        self.bump_significant(&mut children);
        self.bump_significant(&mut children);
        while let Some(token) = self.peek() {
            if matches!(token.kind, NEWLINE) {
                break;
            }
            children.push(self.bump());
        }
        Self::node(MACRO_DEF, children)
    }

    /// `( [expr] {, [expr]} )`: empty arguments are omitted ones.
    fn arg_list(&mut self, depth: usize) -> GreenElement {
        let open = self.pos;
        let mut children = vec![self.bump()];
        loop {
            match self.significant_kind() {
                Some(COMMA) => self.bump_significant(&mut children),
                Some(R_PAREN) => {
                    self.bump_significant(&mut children);
                    break;
                }
                Some(_) => {
                    self.trivia(&mut children);
                    let Some(argument) = self.expr_bp(0, depth + 1, "an argument") else {
                        self.close_paren(open, &mut children, false);
                        break;
                    };
                    children.push(argument);
                    if !matches!(self.significant_kind(), Some(COMMA | R_PAREN)) {
                        self.close_paren(open, &mut children, true);
                        break;
                    }
                }
                None => {
                    self.close_paren(open, &mut children, true);
                    break;
                }
            }
        }
        Self::node(ARG_LIST, children)
    }

    /// The `)` that closes the `(` at `open`, into `children`. Anything
    /// before a `)` later on the line is kept in an `ERROR` node and
    /// reported once (unless `report_skipped` is false: a missing value was
    /// reported already); without a `)` the `(` is unclosed.
    fn close_paren(&mut self, open: usize, children: &mut Vec<GreenElement>, report_skipped: bool) {
        let Some(close) = self.matching_paren(self.pos) else {
            self.report(E::UnclosedParenthesis, open..open + 1, "`(` is not closed by `)` on its line");
            return;
        };
        self.trivia(children);
        if self.pos < close {
            let start = self.pos;
            let mut skipped = Vec::new();
            while self.pos < close {
                skipped.push(self.bump());
            }
            let text = self.text[start..close].trim_end();
            if report_skipped {
                let message =
                    format!("`{}` is not allowed here: an operator, `,` or `)` must follow", visible::quoted(text));
                self.report(E::UnexpectedCharacter, start..start + text.len(), message);
            }
            children.push(Self::node(ERROR, skipped));
        }
        children.push(self.bump());
    }

    /// Where the `)` is that closes a `(` before `from`, if it is on the
    /// line.
    fn matching_paren(&self, mut from: usize) -> Option<usize> {
        let mut depth = 0usize;
        while let Some(token) = self.token_at(from) {
            match token.kind {
                NEWLINE | COMMENT | UNREAD => return None,
                L_PAREN => depth += 1,
                R_PAREN if depth == 0 => return Some(from),
                R_PAREN => depth -= 1,
                _ => {}
            }
            from += token.len;
        }
        None
    }

    /// `name[i, j]`: `name` with its index.
    fn index_expr(&mut self, name: GreenElement, depth: usize) -> GreenElement {
        let mut children = vec![name];
        self.trivia(&mut children);
        self.index(&mut children, depth);
        Self::node(INDEX_EXPR, children)
    }

    /// `[expr {, expr}]` into `children`.
    fn index(&mut self, children: &mut Vec<GreenElement>, depth: usize) {
        let open = self.pos;
        children.push(self.bump());
        loop {
            self.trivia(children);
            if let Some(index) = self.expr_bp(0, depth + 1, "an index inside `[ ]`") {
                children.push(index);
            }
            match self.significant_kind() {
                Some(COMMA) => self.bump_significant(children),
                Some(R_BRACK) => {
                    self.bump_significant(children);
                    return;
                }
                _ => {
                    self.report(E::UnclosedBracket, open..open + 1, "`[` is not closed by `]` on its line");
                    return;
                }
            }
        }
    }

    fn expr(&mut self, what: &str) -> Option<GreenElement> {
        self.expr_bp(0, 0, what)
    }

    fn expr_bp(&mut self, min_bp: u8, depth: usize, what: &str) -> Option<GreenElement> {
        let lhs = self.atom(what, depth)?;
        Some(expr::binary_tail(self, binary, lhs, min_bp, |parser, right, what| parser.expr_bp(right, depth, what)))
    }

    /// A value without binary operators: a literal, a name (indexed or
    /// called), an R parameter, a parenthesised expression, or one of those
    /// after a sign or `NOT`.
    fn atom(&mut self, what: &str, depth: usize) -> Option<GreenElement> {
        let Some(next) = self.significant_at(self.pos).filter(|next| next.range.0 == self.pos) else {
            self.missing(what);
            return None;
        };
        let text = self.text_at(next.range.0);
        // A leading `<<` converts its operand to a string: `<<R1`.
        let prefix = matches!(next.kind, PLUS | MINUS | CONCAT)
            || (next.kind == IDENT && (text.eq_ignore_ascii_case("NOT") || text.eq_ignore_ascii_case("B_NOT")));
        if depth >= MAX_DEPTH && (prefix || matches!(next.kind, L_PAREN | L_BRACK | IDENT | LETTER)) {
            self.report(
                E::ExpectedExpression,
                next.range.0..next.range.1,
                format!("expression nested more than {MAX_DEPTH} deep"),
            );
            return None;
        }
        if prefix {
            let power = if next.kind == CONCAT { CONVERSION_POWER } else { PREFIX_POWER };
            let what = format!("a value after `{text}`");
            let mut children = vec![self.bump()];
            self.trivia(&mut children);
            if let Some(operand) = self.expr_bp(power, depth + 1, &what) {
                children.push(operand);
            }
            return Some(Self::node(PREFIX_EXPR, children));
        }
        match next.kind {
            NUMBER => {
                let mut children = Vec::new();
                expr::number(self, &mut children);
                Some(Self::node(LITERAL, children))
            }
            STRING => Some(Self::node(LITERAL, vec![self.bump()])),
            L_PAREN => {
                let open = self.pos;
                let mut children = vec![self.bump()];
                self.trivia(&mut children);
                let inner = self.expr_bp(0, depth + 1, "an expression inside the parentheses");
                let complete = inner.is_some();
                children.extend(inner);
                // A list of values, which initialises an array: `(1,2,3)`.
                let mut kind = BRACKET_EXPR;
                while self.significant_kind() == Some(COMMA) {
                    kind = ARG_LIST;
                    self.bump_significant(&mut children);
                    self.trivia(&mut children);
                    if let Some(value) = self.expr_bp(0, depth + 1, "a value of the list") {
                        children.push(value);
                    }
                }
                self.close_paren(open, &mut children, complete);
                Some(Self::node(kind, children))
            }
            LETTER if self.is_parameter_at(self.pos) => Some(self.param_ref()),
            LETTER => {
                // An axis or a one-letter variable: `X`, `X1`.
                let mut name = vec![self.bump()];
                if self.kind_at(self.pos) == Some(NUMBER) && !self.text_at(self.pos).contains('.') {
                    name.push(self.bump());
                }
                Some(self.postfix(Self::node(NAME_REF, name), depth))
            }
            IDENT => {
                let name = self.bump();
                if self.significant_kind() == Some(L_PAREN) {
                    let mut children = vec![name];
                    self.trivia(&mut children);
                    children.push(self.arg_list(depth));
                    return Some(Self::node(CALL_EXPR, children));
                }
                Some(self.postfix(Self::node(NAME_REF, vec![name]), depth))
            }
            _ => {
                self.missing(what);
                None
            }
        }
    }

    /// A name with its index, if one follows.
    fn postfix(&mut self, name: GreenElement, depth: usize) -> GreenElement {
        if self.significant_kind() == Some(L_BRACK) { self.index_expr(name, depth) } else { name }
    }

    fn missing(&mut self, what: &str) {
        let pos = self.pos;
        let range = match self.significant_at(pos) {
            Some(next) if next.range.0 == pos => next.range.0..next.range.1,
            _ => pos..pos,
        };
        self.report(E::ExpectedExpression, range, format!("expected {what}"));
    }
}

#[cfg(test)]
mod tests {
    use super::parse_source_file_with;

    /// Parsing in parts gives the tree and the errors of one pass.
    #[test]
    fn parts_parse_like_one_pass() {
        let pieces = [
            "N10 G1 X=R1+2 Y-3.5 F100 ; cut\n",
            "IF R1>2 GOTOF LABEL\r\n",
            "LABEL: DEF REAL A[2,3]=(1,2,3) MSG(\"x\"<<R1)\n",
            "WHILE R1<3 ; loop\n",
            "MSG(\"unclosed\n",
            // More doubled points on a line than a report keeps.
            &"X1.2. ".repeat(20),
            "\n",
            &"X1 Z2 ".repeat(200),
            "\n",
        ];
        let mut text = String::from("%_N_PARTS_MPF\n");
        for i in 0..3000 {
            text.push_str(pieces[i % pieces.len()]);
        }
        text.push_str("M30\n");
        let sequential = parse_source_file_with(&text, usize::MAX);
        assert!(!sequential.1.is_empty() && !sequential.2.is_empty(), "errors kept and left out");
        let parallel = parse_source_file_with(&text, 0);
        assert_eq!(sequential, parallel);
        assert_eq!(rowan::SyntaxNode::<crate::NcLanguage>::new_root(parallel.0).to_string(), text);
    }
}

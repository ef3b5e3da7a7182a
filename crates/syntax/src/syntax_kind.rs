//! The kinds of tokens and nodes in the tree, shared by every dialect.

/// Every token and node kind. Tokens come first, nodes after `__LAST_TOKEN`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(u16)]
#[allow(non_camel_case_types)]
pub enum SyntaxKind {
    // Trivia.
    /// Spaces and tabs.
    WHITESPACE = 0,
    /// `\n`, `\r\n` or a lone `\r`.
    NEWLINE,
    /// A comment: CNC8x6 `"…"` (or `"…` up to the end of the line); ISO
    /// `(…)` (or `(…` up to the end of the line) and `;…` to the end of the
    /// line; Sinumerik `;…` only.
    COMMENT,
    /// Text before the program header `%`, which the control skips while loading.
    PREAMBLE,
    /// Text the control never reads: after CNC8x6's physical end `*`, after
    /// the closing tape mark `%` of an ISO program.
    TRAILER,
    /// The rest of a line past the bytes ncc reads of it
    /// (`MAX_READ_LINE`): only a line far longer than the control's limit
    /// has it.
    UNREAD,

    // Tokens with meaning.
    /// One address letter (`X`, `G`, `N`, …) in any case.
    LETTER,
    /// Digits with an optional decimal point: `12`, `12.`, `.5`, `0.250`.
    NUMBER,
    PLUS,
    /// `-`, or the typographic minus copied from printed manuals.
    MINUS,
    /// `&`, the length-compensation address.
    AMP,
    EQ,
    /// `/`: block skip, or division in an expression.
    SLASH,
    /// `%`: CNC8x6's program header, an ISO tape mark.
    PERCENT,
    /// `*`: CNC8x6's physical end of the program, multiplication in an
    /// expression.
    STAR,
    /// A run of letters that is a keyword, an operator or a function name:
    /// `GOTO`, `WHILE`, `EQ`, `SIN`; Sinumerik: any name (two letters or
    /// `_` first, then letters, digits and `_`), and `$` with a name.
    IDENT,
    /// `#`, which makes a variable of the value after it: `#100`.
    HASH,
    /// `[`, opening a bracketed expression.
    L_BRACK,
    /// `]`, closing a bracketed expression.
    R_BRACK,
    /// `,`, before a corner word: the `,` of `,C1.`.
    COMMA,
    /// Characters the language does not know.
    ERROR_TOKEN,
    /// Sinumerik: a string `"…"` (or `"…` up to the end of the line), or a
    /// quoted constant `'H1F'`.
    STRING,
    /// `(`: Sinumerik arguments and grouping.
    L_PAREN,
    /// `)`.
    R_PAREN,
    /// `:`: after a Sinumerik label, or the main block number `:10`.
    COLON,
    /// `==`.
    EQ_EQ,
    /// `<>`.
    NEQ,
    /// `<`.
    LT,
    /// `<=`.
    LT_EQ,
    /// `>`.
    GT,
    /// `>=`.
    GT_EQ,
    /// `<<`, Sinumerik string concatenation.
    CONCAT,

    #[doc(hidden)]
    __LAST_TOKEN,

    // Nodes.
    SOURCE_FILE,
    /// `%` with the program number and its comment; Sinumerik: a file
    /// header line `%_N_NAME_MPF`.
    HEADER,
    /// A run of consecutive blocks. Runs mean nothing: they bound how much
    /// of the tree an edit rebuilds (a flat root with a million children is
    /// copied whole on every change). Where a run ends depends only on the
    /// blocks' text, so an incremental reparse gives the same runs as a
    /// full parse.
    BLOCK_RUN,
    /// One block. CNC8x6: from its `N` word up to the next `N` or the end;
    /// ISO dialects: one line, with its line break.
    BLOCK,
    /// An address with its value: `X-12.5`, `G01`, `FR10`, `&1201`,
    /// `X#1`, `Z[#2*2]`, and the corner words `,C1.` / `,R2.`.
    WORD,
    /// A parameter used as a value: the `R10` in `FR10`; Sinumerik: `R10`,
    /// `R[R1+2]`.
    PARAM_REF,
    /// A parameter assignment: `R12=-0.864`.
    PARAM_ASSIGN,
    /// Block skip `/`, with the digit the control ignores.
    BLOCK_SKIP,
    /// `*` and everything after it.
    END,
    /// An ISO tape mark `%` on its own line; the closing one holds all the
    /// text after it, which the control never reads.
    TAPE_MARK,
    /// The program number that starts an ISO program: `O1234`, with its
    /// title comment `(NAME)` in the block.
    PROGRAM_NUMBER,
    /// A variable: `#100`, `#[#1+2]`.
    VAR_REF,
    /// An assignment to a variable: `#1 = #2 + 1`; Sinumerik: `R1=5`,
    /// `A[1,2]=3`, `$TC_DP1[1,1]=120`, and the multi-letter addresses
    /// (`CR=10`, `SD=3`), which only the catalogue tells from variables.
    ASSIGN,
    /// A binary operation: `#1 + 2`, `#1 EQ 0`.
    BIN_EXPR,
    /// A sign before a value: `-#5`, `-[#1]`.
    PREFIX_EXPR,
    /// An expression in brackets: `[#1 + 2]`; Sinumerik: in parentheses,
    /// `(R1 + 2)`.
    BRACKET_EXPR,
    /// A function applied to its bracketed argument: `SIN[30.]`,
    /// `ATAN[#1]/[#2]`.
    CALL_EXPR,
    /// A number in an expression.
    LITERAL,
    /// A conditional: `IF [cond] GOTO n`, `IF [cond] THEN #1 = …`;
    /// Sinumerik: `IF cond` opening a block structure, or `IF cond GOTOF L`.
    IF_STMT,
    /// A jump: `GOTO 10`, `GOTO #1`; Sinumerik: `GOTOF LABEL`, `GOTOB N10`,
    /// `GOTO "N"<<R3`.
    GOTO_STMT,
    /// The start of a loop: `WHILE [cond] DO1`, or `DO1` alone; Sinumerik:
    /// `WHILE cond`, `FOR I=1 TO 10`, `REPEAT`, `LOOP`.
    LOOP_START,
    /// The end of a loop: `END1`; Sinumerik: `ENDWHILE`, `ENDFOR`,
    /// `ENDLOOP`, `UNTIL cond`.
    LOOP_END,
    /// Sinumerik `N10` or `:10` at the start of a block.
    BLOCK_NUMBER,
    /// Sinumerik jump label `NAME:`.
    LABEL,
    /// A name used as a value or a target: a variable, a system variable
    /// `$P_F`, an axis `X1`, a label, a constant `TRUE`.
    NAME_REF,
    /// An indexed name: `A[1,I+1]`, `$P_UIFR[1,X,TR]`, `G[8]`.
    INDEX_EXPR,
    /// Arguments in parentheses, empty ones allowed: `(,TRUE,2.14)`.
    ARG_LIST,
    /// A named command or subprogram call on its own: `TRAORI`,
    /// `CYCLE81(10,0,2)`, `MSG("…")`, `MCALL CYCLE81(…)`, `PROFIL`.
    CALL_STMT,
    /// `DEF [scope] type declarations`.
    DEF_STMT,
    /// A type in a definition or a parameter list: `REAL`, `STRING[20]`.
    TYPE,
    /// One declared variable: `A[2,3]`, `B=5`.
    VAR_DECL,
    /// `PROC name (parameters) attributes`.
    PROC_STMT,
    /// A formal parameter: `VAR REAL X[3]`, or a type alone in `EXTERN`.
    PARAM,
    /// `EXTERN name (types)`.
    EXTERN_STMT,
    /// `ELSE`.
    ELSE_STMT,
    /// `ENDIF`.
    ENDIF_STMT,
    /// `CASE expr OF` with its arms.
    CASE_STMT,
    /// One arm of a CASE: `1 GOTOF L1`, `DEFAULT GOTOF L2`.
    CASE_ARM,
    /// A synchronous action: `WHENEVER cond DO actions`, or `DO actions`.
    SYNC_ACTION,
    /// A macro: `DEFINE name AS text`, the text kept as tokens.
    MACRO_DEF,
    /// Input the parser could not place; always comes with a syntax error.
    ERROR,
}

impl SyntaxKind {
    const LAST: u16 = SyntaxKind::ERROR as u16;

    pub fn is_trivia(self) -> bool {
        matches!(
            self,
            SyntaxKind::WHITESPACE
                | SyntaxKind::NEWLINE
                | SyntaxKind::COMMENT
                | SyntaxKind::PREAMBLE
                | SyntaxKind::TRAILER
                | SyntaxKind::UNREAD
        )
    }

    pub fn is_token(self) -> bool {
        (self as u16) < SyntaxKind::__LAST_TOKEN as u16
    }

    fn from_raw(raw: u16) -> SyntaxKind {
        assert!(raw <= Self::LAST, "invalid syntax kind {raw}");
        // The table mirrors the enum order; a test checks it.
        ALL_KINDS[raw as usize]
    }
}

const ALL_KINDS: [SyntaxKind; SyntaxKind::LAST as usize + 1] = {
    use SyntaxKind::*;
    [
        WHITESPACE,
        NEWLINE,
        COMMENT,
        PREAMBLE,
        TRAILER,
        UNREAD,
        LETTER,
        NUMBER,
        PLUS,
        MINUS,
        AMP,
        EQ,
        SLASH,
        PERCENT,
        STAR,
        IDENT,
        HASH,
        L_BRACK,
        R_BRACK,
        COMMA,
        ERROR_TOKEN,
        STRING,
        L_PAREN,
        R_PAREN,
        COLON,
        EQ_EQ,
        NEQ,
        LT,
        LT_EQ,
        GT,
        GT_EQ,
        CONCAT,
        __LAST_TOKEN,
        SOURCE_FILE,
        HEADER,
        BLOCK_RUN,
        BLOCK,
        WORD,
        PARAM_REF,
        PARAM_ASSIGN,
        BLOCK_SKIP,
        END,
        TAPE_MARK,
        PROGRAM_NUMBER,
        VAR_REF,
        ASSIGN,
        BIN_EXPR,
        PREFIX_EXPR,
        BRACKET_EXPR,
        CALL_EXPR,
        LITERAL,
        IF_STMT,
        GOTO_STMT,
        LOOP_START,
        LOOP_END,
        BLOCK_NUMBER,
        LABEL,
        NAME_REF,
        INDEX_EXPR,
        ARG_LIST,
        CALL_STMT,
        DEF_STMT,
        TYPE,
        VAR_DECL,
        PROC_STMT,
        PARAM,
        EXTERN_STMT,
        ELSE_STMT,
        ENDIF_STMT,
        CASE_STMT,
        CASE_ARM,
        SYNC_ACTION,
        MACRO_DEF,
        ERROR,
    ]
};

impl From<SyntaxKind> for rowan::SyntaxKind {
    fn from(kind: SyntaxKind) -> Self {
        rowan::SyntaxKind(kind as u16)
    }
}

/// The rowan language of partprograms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum NcLanguage {}

impl rowan::Language for NcLanguage {
    type Kind = SyntaxKind;

    fn kind_from_raw(raw: rowan::SyntaxKind) -> SyntaxKind {
        SyntaxKind::from_raw(raw.0)
    }

    fn kind_to_raw(kind: SyntaxKind) -> rowan::SyntaxKind {
        kind.into()
    }
}

pub type SyntaxNode = rowan::SyntaxNode<NcLanguage>;
pub type SyntaxToken = rowan::SyntaxToken<NcLanguage>;
pub type SyntaxElement = rowan::SyntaxElement<NcLanguage>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raw_round_trip_covers_every_kind() {
        for (raw, kind) in ALL_KINDS.iter().enumerate() {
            assert_eq!(*kind as usize, raw);
            assert_eq!(SyntaxKind::from_raw(raw as u16), *kind);
        }
    }
}

//! The editor's answers for a Sinumerik file: hover from the catalogue,
//! folding of control structures and comment runs, and completion of the
//! catalogue's codes, addresses, keywords and functions, read from the
//! tree; go to definition, references and rename ([`navigation`]), the
//! outline ([`outline`]), signature help ([`signature`]) and the file's
//! own names in completion ([`completion`]), read from the tree and the
//! program model (`crate::sinumerik::model`).

mod completion;
mod navigation;
mod outline;
pub(crate) mod renumber;
mod signature;
mod walked;

use nc_exec::sinumerik::frames::FrameCommand;
use ncc_catalog::{AddressRole, Catalogue, Item};
use ncc_syntax::{Dialect, SyntaxKind, SyntaxNode, SyntaxToken, TextRange, TextSize};

pub(crate) use self::{
    navigation::{goto_definition, prepare_rename, references, rename},
    outline::document_symbols,
    signature::signature_help,
};
use super::{
    HoverResult,
    completion::{CompletionItem, CompletionKind, Site, Written},
    folding::{Fold, FoldKind, with_comment_runs},
};
use crate::db::{Db, SourceFile};

fn catalogue() -> &'static Catalogue {
    Dialect::Sinumerik.catalogue()
}

/// The catalogue's text for what the control knows; for a name the
/// program gives (a variable, a label, a jump's target, a program), its
/// definition ([`navigation::hover`]).
pub(crate) fn hover(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<HoverResult> {
    let token = token_at(&file.parse(db).syntax_node(), offset)?;
    let explained = || {
        let (query, range) = query_of(&token)?;
        let catalogue = catalogue();
        let items = catalogue.items(&query)?;
        let item = items.iter().find(|item| !matches!(item, Item::Group(_)))?;
        Some(HoverResult { range, markdown: item.markdown(catalogue) })
    };
    // Only names ask the program model: a hover over a code after an edit
    // does not wait for it.
    let named = token.kind() == SyntaxKind::IDENT
        || token.parent_ancestors().any(|node| matches!(node.kind(), SyntaxKind::GOTO_STMT | SyntaxKind::LABEL));
    // CR, unless a variable of that name: also the arc it chooses; a frame
    // command: also the frame it leaves.
    let explained = || {
        let mut hover = explained()?;
        let walked = if token.text().eq_ignore_ascii_case("CR") {
            walked::radius_arc(db, file, offset)
        } else if FrameCommand::from_name(token.text()).is_some() {
            walked::composed_frame(db, file, offset)
        } else {
            None
        };
        if let Some(walked) = walked {
            hover.markdown = format!("{walked}\n\n---\n\n{}", hover.markdown);
        }
        Some(hover)
    };
    if named { navigation::hover(db, file, offset).or_else(explained) } else { explained() }
}

/// The significant token at `offset`; at the boundary of two, the one
/// after it, else the one before (the cursor after a word's last letter).
fn token_at(root: &SyntaxNode, offset: TextSize) -> Option<SyntaxToken> {
    if offset > root.text_range().end() {
        return None;
    }
    let mut candidates = root.token_at_offset(offset).filter(|token| !token.kind().is_trivia());
    let first = candidates.next();
    candidates.next().or(first)
}

/// What to ask the catalogue about `token`, and the text it describes: a
/// name as written (`GOTOF`, `SOFT`, `SUBSTR`, `$P_UIFR`, `CR`,
/// `CYCLE800`), `<<`, a word by its code (`G642`) or its address (`X`),
/// an R parameter, a block number's address.
fn query_of(token: &SyntaxToken) -> Option<(String, TextRange)> {
    let parent = token.parent()?;
    match (token.kind(), parent.kind()) {
        (SyntaxKind::IDENT | SyntaxKind::CONCAT, _) => Some((token.text().to_owned(), token.text_range())),
        (_, SyntaxKind::WORD) => Some((word_query(&parent)?, parent.text_range())),
        (_, SyntaxKind::PARAM_REF) => {
            let number = parent.children_with_tokens().find(|child| child.kind() == SyntaxKind::NUMBER);
            let query = match number.and_then(|number| number.as_token()?.text().parse::<u32>().ok()) {
                Some(number) => format!("param:{number}"),
                None => "R".to_owned(),
            };
            Some((query, parent.text_range()))
        }
        (SyntaxKind::LETTER, SyntaxKind::BLOCK_NUMBER) => Some((token.text().to_owned(), parent.text_range())),
        _ => None,
    }
}

/// `G642` for a code word, the letter for any other address.
fn word_query(word: &SyntaxNode) -> Option<String> {
    let (letter, code) = word_code(word)?;
    let letter = char::from(letter);
    Some(code.map_or_else(|| letter.to_string(), |code| format!("{letter}{code}")))
}

/// A word's (upper-case) letter, and its number when the letter is a
/// code's and the number a whole one.
fn word_code(word: &SyntaxNode) -> Option<(u8, Option<u32>)> {
    let mut tokens = word.children_with_tokens().filter_map(|child| child.into_token());
    let letter = tokens.next().filter(|token| token.kind() == SyntaxKind::LETTER)?.text().as_bytes()[0];
    let letter = letter.to_ascii_uppercase();
    let number = tokens.find(|token| token.kind() != SyntaxKind::WHITESPACE).filter(|t| t.kind() == SyntaxKind::NUMBER);
    let is_code = catalogue().role_of(letter) == Some(AddressRole::Function);
    Some((letter, number.and_then(|number| number.text().parse().ok()).filter(|_| is_code)))
}

/// The file's blocks, in order: the children of its block runs, as the
/// lowering reads them.
fn blocks(root: &SyntaxNode) -> impl Iterator<Item = SyntaxNode> {
    let runs = root.children().filter(|node| node.kind() == SyntaxKind::BLOCK_RUN);
    runs.flat_map(|run| run.children()).filter(|node| node.kind() == SyntaxKind::BLOCK)
}

/// A block's line without its line break and trailing blanks.
fn line_range(text: &str, block: &SyntaxNode) -> TextRange {
    let range = block.text_range();
    TextRange::at(range.start(), TextSize::of(text[range].trim_end()))
}

/// The block structures `IF`…`ENDIF`, `WHILE`…`ENDWHILE`, `FOR`…`ENDFOR`,
/// `REPEAT`…`UNTIL` and `LOOP`…`ENDLOOP`, matched by a stack (an end
/// without its start closes nothing), and the runs of comment lines.
/// Each block's start with the number of structures (IF, WHILE, FOR,
/// REPEAT, LOOP) whose body holds it, for the formatter's indentation.
pub(crate) fn nesting_levels(db: &dyn Db, file: SourceFile) -> Vec<(TextSize, u32)> {
    let model = crate::sinumerik::model::file_model(db, file);
    let spans = model.model.structures.iter().map(|s| (s.start, s.middle, s.end));
    let starts: Vec<TextSize> = model.ranges.iter().map(|range| range.start()).collect();
    super::levels(spans, &starts)
}

pub(crate) fn folding_ranges(db: &dyn Db, file: SourceFile) -> Vec<Fold> {
    let text = file.text(db);
    let root = file.parse(db).syntax_node();
    let mut open: Vec<(&str, TextSize)> = Vec::new();
    let mut folds = Vec::new();
    for block in blocks(&root) {
        for statement in block.children() {
            match structure(&statement) {
                Some(Structure::Start(end)) => open.push((end, block.text_range().start())),
                Some(Structure::End(word)) => {
                    if let Some(at) = open.iter().rposition(|(end, _)| *end == word) {
                        let start = open[at].1;
                        open.truncate(at);
                        folds.push(Fold {
                            range: TextRange::new(start, line_range(text, &block).end()),
                            kind: FoldKind::Region,
                        });
                    }
                }
                None => {}
            }
        }
    }
    with_comment_runs(db, file, folds)
}

enum Structure {
    /// Opens a structure that the word given closes.
    Start(&'static str),
    End(&'static str),
}

/// What a statement does to the block structures: `IF` with a jump opens
/// none; `REPEAT` with labels repeats a section and is a call.
fn structure(statement: &SyntaxNode) -> Option<Structure> {
    let keyword = statement.first_token().filter(|token| token.kind() == SyntaxKind::IDENT)?;
    let word = keyword.text().to_ascii_uppercase();
    match statement.kind() {
        SyntaxKind::IF_STMT if !statement.children().any(|child| child.kind() == SyntaxKind::GOTO_STMT) => {
            Some(Structure::Start("ENDIF"))
        }
        SyntaxKind::ENDIF_STMT => Some(Structure::End("ENDIF")),
        SyntaxKind::LOOP_START => Some(Structure::Start(match word.as_str() {
            "WHILE" => "ENDWHILE",
            "FOR" => "ENDFOR",
            "REPEAT" => "UNTIL",
            "LOOP" => "ENDLOOP",
            _ => return None,
        })),
        SyntaxKind::LOOP_END => {
            ["ENDWHILE", "ENDFOR", "UNTIL", "ENDLOOP"].into_iter().find(|end| *end == word).map(Structure::End)
        }
        _ => None,
    }
}

/// Where a word starts (after a blank or at the line's start): the codes
/// and addresses, then the keywords and functions; after an operator, a
/// parenthesis or `=`, the functions. Nothing in a comment, a string or
/// a system variable's name.
pub(crate) fn completions(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<CompletionItem> {
    let text = file.text(db);
    let root = file.parse(db).syntax_node();
    // A cursor after a line break is on the next line.
    let holds = |block: &SyntaxNode| {
        let range = block.text_range();
        range.contains(offset) || (range.end() == offset && !text[range].ends_with(['\n', '\r']))
    };
    let Some(block) = blocks(&root).find(holds) else { return Vec::new() };
    let start = block.text_range().start();
    // An offset inside a character (a position no editor sends) has no text before it.
    let Some(before) = text.get(std::ops::Range::from(TextRange::new(start, offset))) else { return Vec::new() };
    if before.ends_with('\r') || in_comment_or_string(before) {
        return Vec::new();
    }
    let typed = before.len() - before.trim_end_matches(|c: char| c.is_ascii_alphanumeric() || c == '_').len();
    let word_start = before.len() - typed;
    let replace = TextRange::new(TextSize::of(&before[..word_start]), TextSize::of(before));
    let catalogue = catalogue();
    let site = Site::new(db, Dialect::Sinumerik, start, written(&block));
    let preceding = before[..word_start].chars().next_back();
    if preceding == Some('$') {
        let with_dollar = TextRange::new(replace.start() - TextSize::of('$'), replace.end());
        return completion::system_variables(&site, with_dollar);
    }
    let words: Vec<&str> = before[..word_start].split_whitespace().collect();
    if words.last().is_some_and(|word| completion::takes_label(word)) {
        return completion::labels(db, file, &site, replace);
    }
    let mut items = Vec::new();
    let word_starts = preceding.is_none_or(|c| c == ' ' || c == '\t');
    if word_starts {
        let typed_word = (typed > 0).then_some(replace);
        items = site.new_word(typed_word, replace);
        for keyword in &catalogue.keywords {
            let documentation = Item::Keyword(keyword).markdown(catalogue);
            items.push(site.item(
                keyword.word.clone(),
                CompletionKind::Keyword,
                keyword.title.clone(),
                Some(documentation),
                replace,
            ));
        }
    }
    items.extend(completion::variables(db, file, &site, replace));
    for function in &catalogue.functions {
        let documentation = Item::Function(function).markdown(catalogue);
        items.push(site.item(
            function.name.clone(),
            CompletionKind::Function,
            function.title.clone(),
            Some(documentation),
            replace,
        ));
    }
    if word_starts {
        items.extend(completion::programs(db, file, &site, replace));
    }
    items
}

/// Whether the end of `line` is inside a `;` comment or a string.
fn in_comment_or_string(line: &str) -> bool {
    let mut in_string = false;
    for c in line.chars() {
        match c {
            '"' => in_string = !in_string,
            ';' if !in_string => return true,
            _ => {}
        }
    }
    in_string
}

/// The block's words and code words (ranges in the block), as the neutral
/// lists read them.
fn written(block: &SyntaxNode) -> Written {
    let start = block.text_range().start();
    let mut written = Written::default();
    for word in block.children().filter(|node| node.kind() == SyntaxKind::WORD) {
        let Some((letter, code)) = word_code(&word) else { continue };
        let range = word.text_range() - start;
        written.words.push((letter, range));
        if let Some(number) = code {
            written.codes.push((letter, number, range));
        }
    }
    written
}

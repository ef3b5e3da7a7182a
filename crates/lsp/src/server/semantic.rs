//! Semantic tokens: the analysis's highlight kinds as the protocol's token
//! types and modifiers.
//!
//! Codes are `keyword` tokens (the preparatory functions, G) or `macro`
//! tokens (the others, M: functions the machine carries out), as the
//! catalogue's function letters say, with a modifier naming their
//! catalogue group (`g1` plane, `g3` radius compensation, `m2`
//! spindle, …) in files of the dialect the legend names, so a theme can
//! colour groups apart; parameters are
//! variables, assigned ones with `declaration`. Sinumerik's labels are
//! labels (`declaration` where defined), its calls by name functions, and
//! its system variables properties: the control's state, as addresses are.

use ncc_analysis::{Dialect, HighlightKind, HighlightRange};
use ncc_catalog::AddressRole;
use tower_lsp_server::ls_types as lsp;

use super::convert::LineMap;

const TYPES: [&str; 12] = [
    "keyword", "macro", "property", "function", "label", "variable", "number", "comment", "operator", "error", "type",
    "string",
];
const DECLARATION: u32 = 1;

fn type_index(name: &str) -> u32 {
    TYPES.iter().position(|&t| t == name).expect("a declared token type") as u32
}

/// The dialect whose groups the legend names: the legend is declared at
/// initialize, before any document is open, so it is the default
/// dialect's. Codes of another dialect get no group modifier, which would
/// name a group of this one.
fn legend_dialect() -> Dialect {
    Dialect::default()
}

/// The group modifiers: one per G and M group of the legend's dialect, in
/// catalogue order, after `declaration`.
fn group_modifiers() -> Vec<String> {
    legend_dialect().catalogue().groups.iter().map(|group| group.id.to_ascii_lowercase()).collect()
}

pub(crate) fn legend() -> lsp::SemanticTokensLegend {
    let mut modifiers = vec![lsp::SemanticTokenModifier::DECLARATION];
    modifiers.extend(group_modifiers().into_iter().map(lsp::SemanticTokenModifier::from));
    lsp::SemanticTokensLegend {
        token_types: TYPES.iter().map(|&t| lsp::SemanticTokenType::new(t)).collect(),
        token_modifiers: modifiers,
    }
}

/// The token type and modifier bits of a kind in a file of `dialect`.
fn classify(kind: HighlightKind, dialect: Dialect) -> (u32, u32) {
    let preparatory = dialect.catalogue().preparatory_letter();
    let named = dialect == legend_dialect();
    let group_bit = |group: Option<u8>| group.filter(|&g| named && g < 31).map_or(0, |g| 1 << (u32::from(g) + 1));
    match kind {
        HighlightKind::Code { letter, group } if Some(letter) == preparatory => {
            (type_index("keyword"), group_bit(group))
        }
        HighlightKind::Code { group, .. } => (type_index("macro"), group_bit(group)),
        HighlightKind::Address(AddressRole::Label) => (type_index("function"), 0),
        HighlightKind::Address(AddressRole::Tool | AddressRole::Offset | AddressRole::LengthCompensation) => {
            (type_index("type"), 0)
        }
        HighlightKind::Address(_) | HighlightKind::UnknownAddress => (type_index("property"), 0),
        HighlightKind::BlockNumber => (type_index("label"), 0),
        HighlightKind::Parameter { write } => (type_index("variable"), if write { DECLARATION } else { 0 }),
        HighlightKind::Number => (type_index("number"), 0),
        HighlightKind::Comment => (type_index("comment"), 0),
        HighlightKind::Keyword => (type_index("keyword"), 0),
        HighlightKind::Operator => (type_index("operator"), 0),
        HighlightKind::Error => (type_index("error"), 0),
        HighlightKind::String => (type_index("string"), 0),
        HighlightKind::Label { write } => (type_index("label"), if write { DECLARATION } else { 0 }),
        HighlightKind::Function => (type_index("function"), 0),
        HighlightKind::SystemVariable => (type_index("property"), 0),
    }
}

/// Encodes ranges (sorted, on one line each) of a file in `dialect`
/// relative to each other.
pub(crate) fn encode(map: &LineMap, ranges: &[HighlightRange], dialect: Dialect) -> Vec<lsp::SemanticToken> {
    let mut tokens = Vec::with_capacity(ranges.len());
    let (mut line, mut start) = (0, 0);
    for highlight in ranges {
        let range = map.range(highlight.range);
        if range.start.line != range.end.line || range.end.character <= range.start.character {
            continue;
        }
        let delta_line = range.start.line - line;
        let delta_start = if delta_line == 0 { range.start.character - start } else { range.start.character };
        let (token_type, token_modifiers_bitset) = classify(highlight.kind, dialect);
        tokens.push(lsp::SemanticToken {
            delta_line,
            delta_start,
            length: range.end.character - range.start.character,
            token_type,
            token_modifiers_bitset,
        });
        (line, start) = (range.start.line, range.start.character);
    }
    tokens
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_has_a_type_and_groups_fit_the_modifier_bits() {
        for dialect in Dialect::ALL.into_iter() {
            kinds_fit_the_legend(dialect);
        }
    }

    fn kinds_fit_the_legend(dialect: Dialect) {
        let legend = legend();
        assert!(legend.token_modifiers.len() <= 32, "{} modifiers", legend.token_modifiers.len());
        for kind in HighlightKind::all(dialect) {
            let (token_type, modifiers) = classify(kind, dialect);
            assert!((token_type as usize) < legend.token_types.len(), "{kind:?}");
            assert!(modifiers < 1 << legend.token_modifiers.len(), "{kind:?}");
            if let HighlightKind::Code { group: Some(group), .. } = kind
                && modifiers != 0
            {
                assert_eq!(dialect, legend_dialect(), "{kind:?}");
                let name = legend.token_modifiers[usize::from(group) + 1].as_str();
                assert_eq!(name, dialect.catalogue().groups[usize::from(group)].id.to_ascii_lowercase());
            }
        }
    }
}

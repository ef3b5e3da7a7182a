// The Haas lathe TextMate grammar, run by the tokenizer VS Code uses: every
// kind of word, the tape marks as ncc's parser lays a file out, the
// keywords of the catalogue, and the text the control would reject.

import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import * as path from 'node:path';
import { before, describe, test } from 'node:test';
import type { IGrammar } from 'vscode-textmate';
import { root } from './manifest';
import { invalidTokens, loadGrammar, scopesFrom, scopesOfLine, type Token, tokenize as tokenizeWith } from './textmate';

const operations = path.resolve(root, '..', '..', 'crates', 'catalog', 'data', 'haas-lathe', 'operations.toml');

/** The statement words of ncc's Haas lexer; operators and functions come from the catalogue. */
const STATEMENT_KEYWORDS = ['IF', 'THEN', 'GOTO', 'WHILE', 'DO', 'END'];

let grammar: IGrammar;

before(async () => {
  grammar = await loadGrammar('source.haas-lathe');
});

function tokenize(text: string): Token[] {
  return tokenizeWith(grammar, text);
}

/** The catalogue's operators and functions that are written as words. */
function catalogueKeywords(): string[] {
  const symbols = [...readFileSync(operations, 'utf8').matchAll(/^symbol = "([^"]*)"$/gm)].map((match) => match[1]!);
  return symbols.filter((symbol) => /^[A-Z]{2,}$/.test(symbol));
}

const PROGRAM = [
  '%',
  'O01234 (SHAFT)',
  '(T1 ROUGHING) ; ncc:ignore space-in-word',
  'N10 G28 U0 W0',
  'N20 T0101 G97 S1200 M03',
  'N30 G00 X52. Z2. M08',
  'N40 G71 P50 Q90 U0.5 W.1 D1.5 F0.25',
  'N50 G01 X20. ,C1.',
  'N60 Z-30. ,R2.',
  'N70 G02 X30. Z-35. I5. K0 R5. F.1',
  '/ N80 G01 X-0.5 E0.1',
  '/1 N90 G04 P1.',
  '#100 = 3',
  '#[#100+2] = #100 * SIN[30.] + ROUND[#1]',
  'N100 IF [#100 GT 0] GOTO200',
  'N110 WHILE [#101 LE 5] DO1',
  'N120 #101 = #101 + 1 MOD 3',
  'N130 END1',
  'N140 IF [#1 EQ #0] THEN #2 = ATAN[#3]/[#4]',
  'N150 G65 P9010 A1. L2 C-#2',
  'N160 M98 P1000 L2',
  'N170 X-#100 Z[#101*2]',
  'N200 M30',
  '%',
  'N210 G00 X0 (never read)',
].join('\n');

describe('a program between tape marks', () => {
  const line = (number: number) => scopesOfLine(tokenize(PROGRAM), number);

  test('has no invalid token', () => {
    assert.deepEqual(invalidTokens(tokenize(PROGRAM)), []);
  });

  test('tape marks, the program number with its name, and comments', () => {
    assert.deepEqual(line(0), [['%', 'keyword.other.tape-mark.haas-lathe']]);
    assert.deepEqual(line(1), [
      ['O', 'keyword.other.program-number.haas-lathe'],
      ['01234', 'constant.numeric.program-number.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['(', 'punctuation.definition.comment.begin.haas-lathe'],
      ['SHAFT', 'entity.name.section.program-name.haas-lathe'],
      [')', 'punctuation.definition.comment.end.haas-lathe'],
    ]);
    assert.deepEqual(line(2), [
      ['(', 'punctuation.definition.comment.begin.haas-lathe'],
      ['T1 ROUGHING', 'comment.line.parenthesis.haas-lathe'],
      [')', 'punctuation.definition.comment.end.haas-lathe'],
      [' ', 'source.haas-lathe'],
      [';', 'punctuation.definition.comment.haas-lathe'],
      [' ', 'comment.line.semicolon.haas-lathe'],
      ['ncc:ignore', 'keyword.other.directive.ignore.haas-lathe'],
      [' space-in-word', 'comment.line.semicolon.haas-lathe'],
    ]);
  });

  test('block numbers, G and M codes, T, S, U and W', () => {
    assert.deepEqual(line(3), [
      ['N10', 'entity.name.label.block-number.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['G', 'keyword.other.g-code.haas-lathe'],
      ['28', 'keyword.other.g-code.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['U', 'variable.other.axis.haas-lathe'],
      ['0', 'constant.numeric.integer.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['W', 'variable.other.axis.haas-lathe'],
      ['0', 'constant.numeric.integer.haas-lathe'],
    ]);
    assert.deepEqual(line(4).slice(2), [
      ['T', 'support.constant.address.haas-lathe'],
      ['0101', 'constant.numeric.integer.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['G', 'keyword.other.g-code.haas-lathe'],
      ['97', 'keyword.other.g-code.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['S', 'support.constant.address.haas-lathe'],
      ['1200', 'constant.numeric.integer.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['M', 'support.function.m-code.haas-lathe'],
      ['03', 'support.function.m-code.haas-lathe'],
    ]);
    assert.deepEqual(scopesFrom(tokenize(PROGRAM), 'N200', 3).at(-1), ['M30', 'keyword.control.flow.haas-lathe']);
    assert.deepEqual(scopesFrom(tokenize(PROGRAM), 'N160', 3).at(-1), ['M98', 'keyword.control.flow.haas-lathe']);
    assert.deepEqual(scopesFrom(tokenize(PROGRAM), 'N150', 3).at(-1), ['G65', 'keyword.control.flow.haas-lathe']);
  });

  test('numbers with and without a decimal point, and signs', () => {
    assert.deepEqual(line(6).slice(11), [
      ['U', 'variable.other.axis.haas-lathe'],
      ['0.5', 'constant.numeric.decimal.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['W', 'variable.other.axis.haas-lathe'],
      ['.1', 'constant.numeric.decimal.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['D', 'support.constant.address.haas-lathe'],
      ['1.5', 'constant.numeric.decimal.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['F', 'support.constant.address.haas-lathe'],
      ['0.25', 'constant.numeric.decimal.haas-lathe'],
    ]);
    assert.deepEqual(line(6).slice(5, 9), [
      ['P', 'support.constant.address.haas-lathe'],
      ['50', 'constant.numeric.integer.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['Q', 'support.constant.address.haas-lathe'],
    ]);
    assert.deepEqual(line(9).slice(8), [
      ['Z', 'variable.other.axis.haas-lathe'],
      ['-35.', 'constant.numeric.decimal.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['I', 'variable.other.interpolation.haas-lathe'],
      ['5.', 'constant.numeric.decimal.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['K', 'variable.other.interpolation.haas-lathe'],
      ['0', 'constant.numeric.integer.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['R', 'variable.other.interpolation.haas-lathe'],
      ['5.', 'constant.numeric.decimal.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['F', 'support.constant.address.haas-lathe'],
      ['.1', 'constant.numeric.decimal.haas-lathe'],
    ]);
    assert.deepEqual(line(19).slice(4), [
      ['P', 'support.constant.address.haas-lathe'],
      ['9010', 'constant.numeric.integer.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['A', 'variable.other.interpolation.haas-lathe'],
      ['1.', 'constant.numeric.decimal.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['L', 'support.constant.address.haas-lathe'],
      ['2', 'constant.numeric.integer.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['C', 'variable.other.axis.haas-lathe'],
      ['-', 'keyword.operator.sign.haas-lathe'],
      ['#2', 'variable.parameter.haas-lathe'],
    ]);
  });

  test('corner words ,C and ,R', () => {
    assert.deepEqual(line(7).slice(-3), [
      [',', 'punctuation.separator.corner.haas-lathe'],
      ['C', 'support.constant.address.corner.haas-lathe'],
      ['1.', 'constant.numeric.decimal.haas-lathe'],
    ]);
    assert.deepEqual(line(8).slice(2), [
      ['Z', 'variable.other.axis.haas-lathe'],
      ['-30.', 'constant.numeric.decimal.haas-lathe'],
      [' ', 'source.haas-lathe'],
      [',', 'punctuation.separator.corner.haas-lathe'],
      ['R', 'support.constant.address.corner.haas-lathe'],
      ['2.', 'constant.numeric.decimal.haas-lathe'],
    ]);
  });

  test('block delete, with and without its switch, and E', () => {
    assert.deepEqual(line(10).slice(0, 3), [
      ['/', 'keyword.operator.block-skip.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['N80', 'entity.name.label.block-number.haas-lathe'],
    ]);
    assert.deepEqual(line(10).slice(-2), [
      ['E', 'support.constant.address.haas-lathe'],
      ['0.1', 'constant.numeric.decimal.haas-lathe'],
    ]);
    assert.deepEqual(line(11)[0], ['/1', 'keyword.operator.block-skip.haas-lathe']);
  });

  test('macro variables, expressions in brackets and functions', () => {
    assert.deepEqual(line(12), [
      ['#100', 'variable.parameter.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['=', 'keyword.operator.assignment.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['3', 'constant.numeric.integer.haas-lathe'],
    ]);
    assert.deepEqual(line(13), [
      ['#', 'variable.parameter.haas-lathe'],
      ['[', 'punctuation.section.brackets.begin.haas-lathe'],
      ['#100', 'variable.parameter.haas-lathe'],
      ['+', 'keyword.operator.arithmetic.haas-lathe'],
      ['2', 'constant.numeric.integer.haas-lathe'],
      [']', 'punctuation.section.brackets.end.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['=', 'keyword.operator.assignment.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['#100', 'variable.parameter.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['*', 'keyword.operator.arithmetic.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['SIN', 'support.function.builtin.haas-lathe'],
      ['[', 'punctuation.section.brackets.begin.haas-lathe'],
      ['30.', 'constant.numeric.decimal.haas-lathe'],
      [']', 'punctuation.section.brackets.end.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['+', 'keyword.operator.arithmetic.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['ROUND', 'support.function.builtin.haas-lathe'],
      ['[', 'punctuation.section.brackets.begin.haas-lathe'],
      ['#1', 'variable.parameter.haas-lathe'],
      [']', 'punctuation.section.brackets.end.haas-lathe'],
    ]);
    assert.ok(
      tokenize(PROGRAM)
        .filter((token) => token.line === 13 && token.text === '#100')
        .some((token) => token.scopes.includes('meta.brackets.haas-lathe')),
      'the variable inside the brackets is in them',
    );
    assert.deepEqual(line(21).slice(2), [
      ['X', 'variable.other.axis.haas-lathe'],
      ['-', 'keyword.operator.sign.haas-lathe'],
      ['#100', 'variable.parameter.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['Z', 'variable.other.axis.haas-lathe'],
      ['[', 'punctuation.section.brackets.begin.haas-lathe'],
      ['#101', 'variable.parameter.haas-lathe'],
      ['*', 'keyword.operator.arithmetic.haas-lathe'],
      ['2', 'constant.numeric.integer.haas-lathe'],
      [']', 'punctuation.section.brackets.end.haas-lathe'],
    ]);
  });

  test('IF, GOTO, THEN, WHILE, DO and END, comparisons and MOD', () => {
    assert.deepEqual(line(14).slice(2), [
      ['IF', 'keyword.control.conditional.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['[', 'punctuation.section.brackets.begin.haas-lathe'],
      ['#100', 'variable.parameter.haas-lathe'],
      [' ', 'meta.brackets.haas-lathe'],
      ['GT', 'keyword.operator.comparison.haas-lathe'],
      [' ', 'meta.brackets.haas-lathe'],
      ['0', 'constant.numeric.integer.haas-lathe'],
      [']', 'punctuation.section.brackets.end.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['GOTO', 'keyword.control.goto.haas-lathe'],
      ['200', 'entity.name.label.target.haas-lathe'],
    ]);
    assert.deepEqual(line(15)[2], ['WHILE', 'keyword.control.loop.haas-lathe']);
    assert.deepEqual(line(15).at(-1), ['DO1', 'keyword.control.loop.haas-lathe']);
    assert.deepEqual(line(16).slice(-3), [
      ['MOD', 'keyword.operator.arithmetic.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['3', 'constant.numeric.integer.haas-lathe'],
    ]);
    assert.deepEqual(line(17).at(-1), ['END1', 'keyword.control.loop.haas-lathe']);
    assert.deepEqual(line(18).slice(12), [
      ['THEN', 'keyword.control.conditional.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['#2', 'variable.parameter.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['=', 'keyword.operator.assignment.haas-lathe'],
      [' ', 'source.haas-lathe'],
      ['ATAN', 'support.function.builtin.haas-lathe'],
      ['[', 'punctuation.section.brackets.begin.haas-lathe'],
      ['#3', 'variable.parameter.haas-lathe'],
      [']', 'punctuation.section.brackets.end.haas-lathe'],
      ['/', 'keyword.operator.arithmetic.haas-lathe'],
      ['[', 'punctuation.section.brackets.begin.haas-lathe'],
      ['#4', 'variable.parameter.haas-lathe'],
      [']', 'punctuation.section.brackets.end.haas-lathe'],
    ]);
  });

  test('the control never reads what follows the closing tape mark', () => {
    assert.deepEqual(line(23), [['%', 'keyword.other.tape-mark.haas-lathe']]);
    assert.deepEqual(line(24), [['N210 G00 X0 (never read)', 'comment.block.trailer.haas-lathe']]);
  });
});

describe('keywords', () => {
  const keywordScope = /^(keyword\.control|keyword\.operator|support\.function\.builtin)\./;

  test("are the lexer's statement words and the catalogue's operators and functions, no more", () => {
    const rules = JSON.parse(readFileSync(path.join(root, 'syntaxes', 'haas-lathe.tmLanguage.json'), 'utf8'));
    const words = new Set<string>();
    for (const rule of rules.repository.keyword.patterns as { match: string }[]) {
      for (const word of rule.match.match(/[A-Z]{2,}/g) ?? []) {
        words.add(word);
      }
    }
    const expected = [...STATEMENT_KEYWORDS, ...catalogueKeywords()];
    assert.ok(expected.length > STATEMENT_KEYWORDS.length, 'the catalogue has operators and functions');
    assert.deepEqual([...words].sort(), expected.sort());
  });

  test('each is one token, without a word boundary, as the lexer reads them', () => {
    for (const keyword of [...STATEMENT_KEYWORDS, ...catalogueKeywords()]) {
      const [first] = tokenize(`${keyword}[1]`);
      assert.ok(first && first.text.startsWith(keyword), keyword);
      assert.match(first.scopes.at(-1) ?? '', keywordScope, keyword);
    }
  });

  test('a letter that starts no keyword is an address', () => {
    const tokens = tokenize('GOTO5 G05 DO2 D02 EQ E1. NE N1 #1=#2 OR #3 O1 LE1 L1 END3 E3');
    assert.deepEqual(
      tokens.filter((token) => token.text !== ' ').map((token) => [token.text, token.scopes.at(-1)]),
      [
        ['GOTO', 'keyword.control.goto.haas-lathe'],
        ['5', 'entity.name.label.target.haas-lathe'],
        ['G', 'keyword.other.g-code.haas-lathe'],
        ['05', 'keyword.other.g-code.haas-lathe'],
        ['DO2', 'keyword.control.loop.haas-lathe'],
        ['D', 'support.constant.address.haas-lathe'],
        ['02', 'constant.numeric.integer.haas-lathe'],
        ['EQ', 'keyword.operator.comparison.haas-lathe'],
        ['E', 'support.constant.address.haas-lathe'],
        ['1.', 'constant.numeric.decimal.haas-lathe'],
        ['NE', 'keyword.operator.comparison.haas-lathe'],
        ['N1', 'entity.name.label.block-number.haas-lathe'],
        ['#1', 'variable.parameter.haas-lathe'],
        ['=', 'keyword.operator.assignment.haas-lathe'],
        ['#2', 'variable.parameter.haas-lathe'],
        ['OR', 'keyword.operator.logical.haas-lathe'],
        ['#3', 'variable.parameter.haas-lathe'],
        ['O', 'keyword.other.program-number.haas-lathe'],
        ['1', 'constant.numeric.program-number.haas-lathe'],
        ['LE', 'keyword.operator.comparison.haas-lathe'],
        ['1', 'constant.numeric.integer.haas-lathe'],
        ['L', 'support.constant.address.haas-lathe'],
        ['1', 'constant.numeric.integer.haas-lathe'],
        ['END3', 'keyword.control.loop.haas-lathe'],
        ['E', 'support.constant.address.haas-lathe'],
        ['3', 'constant.numeric.integer.haas-lathe'],
      ],
    );
  });

  test('are upper case: in lower case the letters are addresses', () => {
    const tokens = tokenize('n10 g1 x.5 o2');
    assert.deepEqual(
      tokens.filter((token) => token.text !== ' ').map((token) => [token.text, token.scopes.at(-1)]),
      [
        ['n10', 'entity.name.label.block-number.haas-lathe'],
        ['g', 'keyword.other.g-code.haas-lathe'],
        ['1', 'keyword.other.g-code.haas-lathe'],
        ['x', 'variable.other.axis.haas-lathe'],
        ['.5', 'constant.numeric.decimal.haas-lathe'],
        ['o', 'keyword.other.program-number.haas-lathe'],
        ['2', 'constant.numeric.program-number.haas-lathe'],
      ],
    );
  });
});

describe('tape marks as ncc lays a file out', () => {
  const marks = (text: string) =>
    tokenize(text)
      .filter((token) => token.text.trim() !== '')
      .map((token) => [token.line, token.text, token.scopes.at(-1)]);

  test('blank lines may come before the opening mark', () => {
    assert.deepEqual(marks('\n  \n%\nO1\n%\n'), [
      [2, '%', 'keyword.other.tape-mark.haas-lathe'],
      [3, 'O', 'keyword.other.program-number.haas-lathe'],
      [3, '1', 'constant.numeric.program-number.haas-lathe'],
      [4, '%', 'keyword.other.tape-mark.haas-lathe'],
    ]);
  });

  test('without an opening mark, the first % line ends the program', () => {
    assert.deepEqual(marks('O1\nM30\n  % (END)\nO2'), [
      [0, 'O', 'keyword.other.program-number.haas-lathe'],
      [0, '1', 'constant.numeric.program-number.haas-lathe'],
      [1, 'M30', 'keyword.control.flow.haas-lathe'],
      [2, '%', 'keyword.other.tape-mark.haas-lathe'],
      [2, ' (END)', 'comment.block.trailer.haas-lathe'],
      [3, 'O2', 'comment.block.trailer.haas-lathe'],
    ]);
  });

  test('a comment line before the % makes it the closing mark', () => {
    assert.deepEqual(marks('(HEADER)\n%\nO1').slice(3), [
      [1, '%', 'keyword.other.tape-mark.haas-lathe'],
      [2, 'O1', 'comment.block.trailer.haas-lathe'],
    ]);
  });
});

describe('mistakes', () => {
  test('are marked where the control would reject them', () => {
    const tokens = tokenize(
      [
        'O1 (NAME',
        'N10 G01 V1. X1 % Z2',
        'N20 #1 = # + 2 ] \u20ac',
        'N30 IF [#1 gt 0] GOTO 5',
        'N40 G01 X1. ,A2. Z1 )',
      ].join('\n'),
    );
    assert.deepEqual(scopesOfLine(tokens, 0).slice(-2), [
      ['(', 'punctuation.definition.comment.begin.haas-lathe'],
      ['NAME', 'entity.name.section.program-name.haas-lathe'],
    ]);
    assert.deepEqual(
      invalidTokens(tokens).map((token) => [token.line, token.text, token.scopes.at(-1)]),
      [
        [1, 'V', 'invalid.illegal.address.haas-lathe'],
        [1, '%', 'invalid.illegal.tape-mark.haas-lathe'],
        [2, '#', 'invalid.illegal.variable-without-number.haas-lathe'],
        [2, ']', 'invalid.illegal.character.haas-lathe'],
        [2, '\u20ac', 'invalid.illegal.character.haas-lathe'],
        [3, 'g', 'invalid.illegal.letter-in-expression.haas-lathe'],
        [3, 't', 'invalid.illegal.letter-in-expression.haas-lathe'],
        [4, ',', 'invalid.illegal.character.haas-lathe'],
        [4, ')', 'invalid.illegal.character.haas-lathe'],
      ],
    );
  });

  test('a slash after the first word divides, and does not skip the block', () => {
    const tokens = tokenize('N10 /2 X1');
    assert.deepEqual(scopesOfLine(tokens, 0).slice(2, 4), [
      ['/', 'keyword.operator.arithmetic.haas-lathe'],
      ['2', 'constant.numeric.integer.haas-lathe'],
    ]);
  });
});

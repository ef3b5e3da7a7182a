// The Sinumerik TextMate grammar, run by the tokenizer VS Code uses: the
// start of a block (skip, number, label), statements, words, strings and
// comments, the catalogue's keywords, functions and word codes, and the
// characters ncc's lexer does not know.

import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import * as path from 'node:path';
import { before, describe, test } from 'node:test';
import type { IGrammar } from 'vscode-textmate';
import { root } from './manifest';
import { invalidTokens, loadGrammar, scopesFrom, scopesOfLine, type Token, tokenize as tokenizeWith } from './textmate';

const data = path.resolve(root, '..', '..', 'crates', 'catalog', 'data', 'sinumerik');

let grammar: IGrammar;

before(async () => {
  grammar = await loadGrammar('source.sinumerik');
});

function tokenize(text: string): Token[] {
  return tokenizeWith(grammar, text);
}

/** The names of a catalogue file's entries: `key = "…"` on the line after each `[[table]]`. */
function catalogue(file: string, table: string, key: string): string[] {
  const text = readFileSync(path.join(data, file), 'utf8');
  return [...text.matchAll(new RegExp(`^\\[\\[${table}\\]\\]\\r?\\n${key} = "([^"]*)"$`, 'gm'))].map((match) => match[1]!);
}

const PROGRAM = [
  '%_N_PART_MPF',
  '; ncc:ignore S024',
  'DEF REAL DEPTH=5.5, TABLE[3]',
  'N10 G17 G54 G642 SOFT X=R1+5 CR=2.5',
  '/1 N20 G0 X10Y-20 Z2 M3 S1200',
  'START: $P_UIFR[1,X,TR]=5',
  'IF DEPTH>=2 GOTOF START',
  'WHILE R[R1]<>0 AND NOT FLAG',
  '  MSG("DEPTH "<<DEPTH)',
  'ENDWHILE',
  'CYCLE81(10,0,2,-5) PROFIL(,TRUE)',
  ':30 M30',
].join('\n');

describe('a program', () => {
  const line = (number: number) => scopesOfLine(tokenize(PROGRAM), number);

  test('has no invalid token', () => {
    assert.deepEqual(invalidTokens(tokenize(PROGRAM)), []);
  });

  test('the header, comments and declarations', () => {
    assert.deepEqual(line(0), [
      ['%', 'keyword.other.header.sinumerik'],
      ['_N_PART_MPF', 'entity.name.section.program-name.sinumerik'],
    ]);
    assert.deepEqual(line(1), [
      [';', 'punctuation.definition.comment.sinumerik'],
      [' ', 'comment.line.semicolon.sinumerik'],
      ['ncc:ignore', 'keyword.other.directive.ignore.sinumerik'],
      [' S024', 'comment.line.semicolon.sinumerik'],
    ]);
    assert.deepEqual(scopesFrom(tokenize(PROGRAM), 'DEF REAL DEPTH=5.5', 7), [
      ['DEF', 'storage.modifier.sinumerik'],
      [' ', 'source.sinumerik'],
      ['REAL', 'storage.type.sinumerik'],
      [' ', 'source.sinumerik'],
      ['DEPTH', 'variable.other.sinumerik'],
      ['=', 'keyword.operator.assignment.sinumerik'],
      ['5.5', 'constant.numeric.decimal.sinumerik'],
    ]);
  });

  test('codes, word codes, addresses and R parameters', () => {
    const words = line(3).filter(([text]) => text.trim() !== '');
    assert.deepEqual(words, [
      ['N10', 'entity.name.label.block-number.sinumerik'],
      ['G17', 'keyword.other.g-code.sinumerik'],
      ['G54', 'keyword.other.g-code.sinumerik'],
      ['G642', 'keyword.other.g-code.sinumerik'],
      ['SOFT', 'keyword.other.g-code.sinumerik'],
      ['X', 'variable.other.axis.sinumerik'],
      ['=', 'keyword.operator.assignment.sinumerik'],
      ['R1', 'variable.parameter.r.sinumerik'],
      ['+', 'keyword.operator.arithmetic.sinumerik'],
      ['5', 'constant.numeric.integer.sinumerik'],
      ['CR', 'support.constant.address.sinumerik'],
      ['=', 'keyword.operator.assignment.sinumerik'],
      ['2.5', 'constant.numeric.decimal.sinumerik'],
    ]);
    const skipped = line(4).filter(([text]) => text.trim() !== '');
    assert.deepEqual(skipped.slice(0, 6), [
      ['/1', 'keyword.operator.block-skip.sinumerik'],
      ['N20', 'entity.name.label.block-number.sinumerik'],
      ['G0', 'keyword.other.g-code.sinumerik'],
      ['X', 'variable.other.axis.sinumerik'],
      ['10', 'constant.numeric.integer.sinumerik'],
      ['Y', 'variable.other.axis.sinumerik'],
    ]);
    assert.deepEqual(line(11).slice(0, 1), [[':30', 'entity.name.label.block-number.sinumerik']]);
    assert.deepEqual(line(11).at(-1), ['M30', 'keyword.control.flow.sinumerik']);
  });

  test('labels, system variables, jumps and conditions', () => {
    assert.deepEqual(line(5).slice(0, 4), [
      ['START', 'entity.name.label.sinumerik'],
      [':', 'punctuation.separator.label.sinumerik'],
      [' ', 'source.sinumerik'],
      ['$P_UIFR', 'variable.language.system.sinumerik'],
    ]);
    assert.deepEqual(
      line(6).filter(([text]) => text.trim() !== ''),
      [
        ['IF', 'keyword.control.sinumerik'],
        ['DEPTH', 'variable.other.sinumerik'],
        ['>=', 'keyword.operator.comparison.sinumerik'],
        ['2', 'constant.numeric.integer.sinumerik'],
        ['GOTOF', 'keyword.control.sinumerik'],
        ['START', 'variable.other.sinumerik'],
      ],
    );
    const loop = line(7).filter(([text]) => text.trim() !== '');
    assert.deepEqual(loop.slice(0, 3), [
      ['WHILE', 'keyword.control.sinumerik'],
      ['R', 'variable.parameter.r.sinumerik'],
      ['[', 'punctuation.section.brackets.sinumerik'],
    ]);
    assert.deepEqual(loop.slice(-4), [
      ['0', 'constant.numeric.integer.sinumerik'],
      ['AND', 'keyword.operator.word.sinumerik'],
      ['NOT', 'keyword.operator.word.sinumerik'],
      ['FLAG', 'variable.other.sinumerik'],
    ]);
  });

  test('strings, concatenation, functions, cycles and subprogram calls', () => {
    assert.deepEqual(scopesFrom(tokenize(PROGRAM), 'MSG("DEPTH "<<', 6), [
      ['MSG', 'support.function.builtin.sinumerik'],
      ['(', 'punctuation.section.parens.sinumerik'],
      ['"', 'punctuation.definition.string.begin.sinumerik'],
      ['DEPTH ', 'string.quoted.double.sinumerik'],
      ['"', 'punctuation.definition.string.end.sinumerik'],
      ['<<', 'keyword.operator.concatenation.sinumerik'],
    ]);
    const calls = line(10).filter(([text]) => /^[A-Z]/.test(text));
    assert.deepEqual(calls, [
      ['CYCLE81', 'support.function.cycle.sinumerik'],
      ['PROFIL', 'entity.name.function.call.sinumerik'],
      ['TRUE', 'constant.language.sinumerik'],
    ]);
  });
});

describe('the catalogue', () => {
  test('every keyword is one token of a keyword scope, in either case', () => {
    const keywords = catalogue('keywords.toml', 'keyword', 'word');
    assert.ok(keywords.includes('GOTOF') && keywords.includes('DEF'));
    for (const word of keywords) {
      for (const written of [word, word.toLowerCase()]) {
        const [first] = tokenize(`${written} `);
        assert.equal(first?.text, written);
        assert.match(first?.scopes.at(-1) ?? '', /^(keyword|storage|constant\.language)\./, written);
      }
    }
  });

  test('every function is a builtin function', () => {
    const functions = catalogue('functions.toml', 'function', 'name');
    assert.ok(functions.includes('SUBSTR') && functions.includes('WORKPIECE'));
    for (const name of functions) {
      const [first] = tokenize(`${name}(1)`);
      assert.deepEqual([first?.text, first?.scopes.at(-1)], [name, 'support.function.builtin.sinumerik']);
    }
  });

  test('every code written as a word is a G code', () => {
    const words = catalogue('codes.toml', 'code', 'code').filter((code) => !/^[GM][0-9]+$/.test(code));
    assert.ok(words.includes('BSPLINE'));
    for (const word of words) {
      const [first] = tokenize(word);
      assert.deepEqual([first?.text, first?.scopes.at(-1)], [word, 'keyword.other.g-code.sinumerik']);
    }
  });
});

describe('what ncc reads differently', () => {
  test('a name that starts like a keyword or an address is a name', () => {
    const names = tokenize('IFX DEFAULTS GOTOFAR XYZ DELKA=1 G_X').filter(({ text }) => text.trim() !== '');
    assert.deepEqual(
      names.map(({ text, scopes }) => [text, scopes.at(-1)]),
      [
        ['IFX', 'variable.other.sinumerik'],
        ['DEFAULTS', 'variable.other.sinumerik'],
        ['GOTOFAR', 'variable.other.sinumerik'],
        ['XYZ', 'variable.other.sinumerik'],
        ['DELKA', 'variable.other.sinumerik'],
        ['=', 'keyword.operator.assignment.sinumerik'],
        ['1', 'constant.numeric.integer.sinumerik'],
        ['G_X', 'variable.other.sinumerik'],
      ],
    );
  });

  test('an unclosed string ends with its line, and unknown characters are invalid', () => {
    const tokens = tokenize('MSG("OPEN\nX10 # ?');
    assert.deepEqual(scopesOfLine(tokens, 1).at(0), ['X', 'variable.other.axis.sinumerik']);
    assert.deepEqual(
      invalidTokens(tokens).map(({ text }) => text),
      ['#', '?'],
    );
  });
});

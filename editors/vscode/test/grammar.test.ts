// The CNC8x6 TextMate grammar, run by the tokenizer VS Code uses, on the
// example programs and on programs with mistakes.

import assert from 'node:assert/strict';
import { promises as fs } from 'node:fs';
import * as path from 'node:path';
import { before, describe, test } from 'node:test';
import type { IGrammar } from 'vscode-textmate';
import { root } from './manifest';
import { invalidTokens, loadGrammar, scopesFrom, scopesOfLine, type Token, tokenize as tokenizeWith } from './textmate';

const examples = path.resolve(root, '..', '..', 'examples');

let grammar: IGrammar;

before(async () => {
  grammar = await loadGrammar('source.cnc8x6');
});

function tokenize(text: string): Token[] {
  return tokenizeWith(grammar, text);
}

async function example(file: string): Promise<Token[]> {
  return tokenize(await fs.readFile(path.join(examples, file), 'utf8'));
}

describe('example programs', () => {
  test('have no invalid token and no preamble', async () => {
    for (const file of ['milling/pocket.NCP', 'milling/holes.NCP', 'lathe/shaft.NCP', 'macros/L9001']) {
      const tokens = await example(file);
      assert.deepEqual(invalidTokens(tokens), [], file);
      assert.ok(!tokens.some((token) => token.scopes.includes('comment.block.preamble.cnc8x6')), file);
    }
  });

  test('pocket.NCP: header, comments, parameters, calls and the end', async () => {
    const tokens = await example('milling/pocket.NCP');
    assert.deepEqual(scopesFrom(tokens, '%', 4), [
      ['%', 'keyword.other.header.cnc8x6'],
      ['101', 'constant.numeric.program-number.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['"', 'punctuation.definition.comment.begin.cnc8x6'],
    ]);
    assert.deepEqual(scopesFrom(tokens, 'N20', 8), [
      ['N20', 'entity.name.label.block-number.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['R10', 'variable.parameter.cnc8x6'],
      ['=', 'keyword.operator.assignment.cnc8x6'],
      ['250', 'constant.numeric.integer.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['"', 'punctuation.definition.comment.begin.cnc8x6'],
      ['F HRUBOVÁNÍ 250 mm/min (BEZ TEČKY)', 'comment.line.double-quote.cnc8x6'],
    ]);
    assert.deepEqual(scopesFrom(tokens, 'R11', 3).at(-1), ['2.', 'constant.numeric.decimal.cnc8x6']);
    assert.deepEqual(scopesFrom(tokens, 'N90', 13), [
      ['N90', 'entity.name.label.block-number.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['G', 'keyword.other.g-code.cnc8x6'],
      ['91', 'keyword.other.g-code.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['X', 'variable.other.axis.cnc8x6'],
      ['20.', 'constant.numeric.decimal.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['Z', 'variable.other.axis.cnc8x6'],
      ['R14', 'variable.parameter.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['F', 'support.constant.address.cnc8x6'],
      ['R12', 'variable.parameter.cnc8x6'],
    ]);
    assert.deepEqual(scopesFrom(tokens, 'N110', 7), [
      ['N110', 'entity.name.label.block-number.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['G71', 'keyword.control.flow.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['L', 'entity.name.function.target.cnc8x6'],
      ['100', 'entity.name.function.target.cnc8x6'],
      [' ', 'source.cnc8x6'],
    ]);
    assert.deepEqual(scopesFrom(tokens, '&', 2), [
      ['&', 'support.constant.address.cnc8x6'],
      ['0010', 'constant.numeric.integer.cnc8x6'],
    ]);
    assert.deepEqual(scopesFrom(tokens, 'M30', 1), [['M30', 'keyword.control.flow.cnc8x6']]);
    assert.deepEqual(scopesFrom(tokens, 'M03', 2), [
      ['M', 'support.function.m-code.cnc8x6'],
      ['03', 'support.function.m-code.cnc8x6'],
    ]);
    assert.deepEqual(scopesFrom(tokens, 'G79', 1), [['G79', 'keyword.control.flow.cnc8x6']]);
    assert.deepEqual(scopesFrom(tokens, '*', 4), [
      ['*', 'keyword.control.end.cnc8x6'],
      [' ', 'meta.after-end.cnc8x6'],
      ['"', 'punctuation.definition.comment.begin.cnc8x6'],
      ['KONEC SOUBORU', 'comment.line.double-quote.cnc8x6'],
    ]);
  });

  test('L9001: arithmetic control words and a jump counted by a parameter', async () => {
    const tokens = await example('macros/L9001');
    assert.deepEqual(scopesFrom(tokens, 'R5', 7), [
      ['R5', 'variable.parameter.cnc8x6'],
      ['=', 'keyword.operator.assignment.cnc8x6'],
      ['-', 'keyword.operator.mode.cnc8x6'],
      ['42', 'keyword.operator.arithmetic.cnc8x6'],
      ['21', 'variable.parameter.operand.cnc8x6'],
      ['02', 'variable.parameter.operand.cnc8x6'],
      ['26', 'variable.parameter.target.cnc8x6'],
    ]);
    assert.deepEqual(scopesFrom(tokens, 'R8', 6).slice(2), [
      ['08', 'keyword.operator.arithmetic.cnc8x6'],
      ['27', 'variable.parameter.operand.cnc8x6'],
      ['00', 'variable.parameter.operand.cnc8x6'],
      ['27', 'variable.parameter.target.cnc8x6'],
    ]);
    assert.deepEqual(scopesFrom(tokens, 'G29', 2), [
      ['G', 'keyword.other.g-code.cnc8x6'],
      ['29', 'keyword.other.g-code.cnc8x6'],
    ]);
    assert.deepEqual(scopesFrom(tokens, 'G73', 8).slice(2), [
      ['L', 'entity.name.function.target.cnc8x6'],
      ['70', 'entity.name.function.target.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['Q', 'support.constant.address.cnc8x6'],
      ['R26', 'variable.parameter.cnc8x6'],
      [' ', 'source.cnc8x6'],
    ]);
  });
});

describe('mistakes and rarer forms', () => {
  test('marks what the control would reject', () => {
    const tokens = tokenize(
      [
        'LOAD %7 "PREAMBLE BEFORE THE HEADER',
        '%7',
        'N10 G01 X- 5 (1) O12',
        'N20 R3 M30',
        '* "END" TRAILING',
      ].join('\n'),
    );
    assert.deepEqual(
      tokens.filter((token) => token.line === 0).map((token) => [token.text, token.scopes.at(-1)]),
      [
        ['LOAD ', 'comment.block.preamble.cnc8x6'],
        ['%', 'keyword.other.header.cnc8x6'],
        ['7', 'constant.numeric.program-number.cnc8x6'],
        [' ', 'source.cnc8x6'],
        ['"', 'punctuation.definition.comment.begin.cnc8x6'],
        ['PREAMBLE BEFORE THE HEADER', 'comment.line.double-quote.cnc8x6'],
      ],
    );
    assert.deepEqual(
      invalidTokens(tokens).map((token) => [token.text, token.scopes.at(-1)]),
      [
        ['-', 'invalid.illegal.stray.cnc8x6'],
        ['5', 'invalid.illegal.stray.cnc8x6'],
        ['(', 'invalid.illegal.character.cnc8x6'],
        ['1', 'invalid.illegal.stray.cnc8x6'],
        [')', 'invalid.illegal.character.cnc8x6'],
        ['O', 'invalid.illegal.address.cnc8x6'],
        ['R3', 'invalid.illegal.parameter-without-assignment.cnc8x6'],
        ['TRAILING', 'invalid.illegal.text-after-end.cnc8x6'],
      ],
    );
  });

  test('reads lowercase addresses, block skip, unclosed and typographic comments, $PC and ncc:ignore', () => {
    const tokens = tokenize(
      [
        '"  $PC - CYCLES',
        'N1 /1 g1 x.5 "ncc:ignore missing-feed',
        'N2 \u201eQUOTED\u201c Y1 "OPEN N3 G0',
        'N4 G04 Q100',
      ].join('\n'),
    );
    const scopes = (line: number) => scopesOfLine(tokens, line);
    assert.deepEqual(scopes(0).slice(1, 3), [
      ['  ', 'comment.line.double-quote.cnc8x6'],
      ['$PC', 'keyword.other.cycle-file.cnc8x6'],
    ]);
    assert.deepEqual(scopes(1), [
      ['N1', 'entity.name.label.block-number.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['/1', 'keyword.operator.block-skip.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['g', 'keyword.other.g-code.cnc8x6'],
      ['1', 'keyword.other.g-code.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['x', 'variable.other.axis.cnc8x6'],
      ['.5', 'constant.numeric.decimal.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['"', 'punctuation.definition.comment.begin.cnc8x6'],
      ['ncc:ignore', 'keyword.other.directive.ignore.cnc8x6'],
      [' missing-feed', 'comment.line.double-quote.cnc8x6'],
    ]);
    assert.deepEqual(scopes(2), [
      ['N2', 'entity.name.label.block-number.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['\u201e', 'invalid.deprecated.typographic-quote.cnc8x6'],
      ['QUOTED', 'comment.line.typographic-quote.cnc8x6'],
      ['\u201c', 'punctuation.definition.comment.end.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['Y', 'variable.other.axis.cnc8x6'],
      ['1', 'constant.numeric.integer.cnc8x6'],
      [' ', 'source.cnc8x6'],
      ['"', 'punctuation.definition.comment.begin.cnc8x6'],
      ['OPEN N3 G0', 'comment.line.double-quote.cnc8x6'],
    ]);
    // The comment left open on the line before ended with that line.
    assert.deepEqual(scopes(3)[0], ['N4', 'entity.name.label.block-number.cnc8x6']);
    assert.deepEqual(invalidTokens(tokens).length, 1, 'only the typographic quote');
  });
});

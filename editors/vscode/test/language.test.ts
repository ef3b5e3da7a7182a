// The language contributions: which files become documents of which
// control's language, which of those go to the server, and what the
// language configurations make of their documents.

import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import * as path from 'node:path';
import { describe, test } from 'node:test';
import { DOCUMENT_SELECTOR, LANGUAGES, TOOLPATH_LANGUAGES } from '../src/documents';
import { languageOf, manifest, root } from './manifest';

interface Contribution {
  id: string;
  configuration?: string;
}

const [language] = manifest.contributes.languages;
const haas = (manifest.contributes.languages as Contribution[]).find((contribution) => contribution.id === 'haas-lathe');

/** The word pattern of a language configuration, with the global flag that VS Code adds. */
function wordPattern(configuration: { wordPattern: { pattern: string; flags: string } }): RegExp {
  return new RegExp(configuration.wordPattern.pattern, configuration.wordPattern.flags + 'g');
}

describe('language contribution', () => {
  test('is cnc8x6, with a grammar and a configuration that exist', () => {
    assert.equal(language.id, 'cnc8x6');
    assert.ok(existsSync(path.join(root, language.configuration)));
    const [grammar] = manifest.contributes.grammars;
    assert.equal(grammar.language, 'cnc8x6');
    assert.ok(existsSync(path.join(root, grammar.path)));
  });

  test('takes partprograms and macrocycle files', () => {
    for (const file of ['examples/milling/pocket.NCP', 'a.ncp', 'PCYKLYDG.NCP', 'L1', 'L9001', 'dir/l12', 'L0100', 'L12.NCP']) {
      assert.equal(languageOf(file), 'cnc8x6', file);
    }
  });

  test('leaves other files alone', () => {
    const others = [
      'L',
      'LICENSE',
      'Lx1',
      'L1a',
      'L12345',
      'L9001.txt',
      'L9001.bak',
      'README.md',
      'NCP',
      'a.NCP.orig',
      'ML9001',
      'MPF',
      'a.MPF.bak',
      'O1234.nc.orig',
      'a.ncx',
      'O',
      'O123456',
      'Oa1',
      'O1234.txt',
      'OS',
    ];
    for (const file of others) {
      assert.equal(languageOf(file), undefined, file);
    }
  });
});

describe('Haas lathe contribution', () => {
  test('has a grammar and a configuration that exist', () => {
    assert.ok(haas?.configuration);
    assert.ok(existsSync(path.join(root, haas.configuration)));
    const grammar = manifest.contributes.grammars.find((g: { language: string }) => g.language === 'haas-lathe');
    assert.equal(grammar.scopeName, 'source.haas-lathe');
    assert.ok(existsSync(path.join(root, grammar.path)));
  });

  test('takes programs by extension, in either case, and program files named by their number', () => {
    const files = ['O1234.nc', 'O1234.NC', 'part.tap', 'PART.TAP', 'O1', 'O1234', 'O01234', 'dir/O99999', 'o0001'];
    for (const file of files) {
      assert.equal(languageOf(file), 'haas-lathe', file);
    }
  });
});

describe('Sinumerik contribution', () => {
  const sinumerik = (manifest.contributes.languages as Contribution[]).find((c) => c.id === 'sinumerik');

  test('main programs and subprograms, in either case', () => {
    for (const file of ['MAIN.MPF', 'main.mpf', 'dir/SUB.SPF', 'sub.spf']) {
      assert.equal(languageOf(file), 'sinumerik', file);
    }
  });

  test('has a grammar and a configuration that exist', () => {
    assert.ok(sinumerik?.configuration);
    assert.ok(existsSync(path.join(root, sinumerik.configuration)));
    const grammar = manifest.contributes.grammars.find((g: { language: string }) => g.language === 'sinumerik');
    assert.equal(grammar.scopeName, 'source.sinumerik');
    assert.ok(existsSync(path.join(root, grammar.path)));
  });

  test('comments a line with a semicolon; a word is a name, a system variable or a number', () => {
    const configuration = JSON.parse(readFileSync(path.join(root, sinumerik?.configuration ?? ''), 'utf8'));
    assert.deepEqual(configuration.comments, { lineComment: ';' });
    const text = 'N10 G642 X=R1+5.5 $P_UIFR[1] CYCLE800(1) "TEXT" ; NOTE';
    assert.deepEqual(text.match(wordPattern(configuration)), [
      'N10',
      'G642',
      'X',
      'R1',
      '5.5',
      '$P_UIFR',
      '1',
      'CYCLE800',
      '1',
      'TEXT',
      'NOTE',
    ]);
  });
});

describe('documents for the server', () => {
  test('are the files of every contributed language', () => {
    const contributed = manifest.contributes.languages.map((language: { id: string }) => language.id);
    assert.deepEqual([...LANGUAGES].sort(), [...contributed].sort());
    const files = DOCUMENT_SELECTOR.filter((selector) => selector.scheme === 'file');
    assert.deepEqual(files.map((selector) => selector.language), [...LANGUAGES]);
  });

  test('without a file name, only CNC8x6, as the server reads them', () => {
    const untitled = DOCUMENT_SELECTOR.filter((selector) => selector.scheme !== 'file');
    assert.deepEqual(untitled, [{ scheme: 'untitled', language: 'cnc8x6' }]);
  });

  test('the toolpath is offered for CNC8x6 and Haas lathe programs, in the menus as in the command', () => {
    assert.deepEqual(TOOLPATH_LANGUAGES, ['cnc8x6', 'haas-lathe']);
    const whens = Object.values(manifest.contributes.menus)
      .flat()
      .filter((item) => (item as { command: string }).command === 'ncc.showToolpath')
      .map((item) => (item as { when: string }).when);
    const when = (key: string) => TOOLPATH_LANGUAGES.map((id) => `${key} == ${id}`).join(' || ');
    assert.deepEqual(whens, [when('resourceLangId'), when('editorLangId')]);
  });
});

describe('CNC8x6 language configuration', () => {
  const configuration = JSON.parse(readFileSync(path.join(root, language.configuration), 'utf8'));

  test('comments a line with a double quote', () => {
    assert.deepEqual(configuration.comments, { lineComment: '"' });
  });

  test('takes a word with its value, a parameter or prose as one word', () => {
    const word = wordPattern(configuration);
    const text = 'N10 G01X-12.5 FR10 R10=250. &0010 %101 "DRÁŽKA R8"';
    assert.deepEqual(text.match(word), ['N10', 'G01', 'X-12.5', 'FR10', 'R10', '250.', '&0010', '%101', 'DRÁŽKA', 'R8']);
  });
});

describe('Haas lathe language configuration', () => {
  const configuration = JSON.parse(readFileSync(path.join(root, haas?.configuration ?? ''), 'utf8'));

  test('comments a line with a semicolon and a selection with parentheses', () => {
    assert.deepEqual(configuration.comments, { lineComment: ';', blockComment: ['(', ')'] });
  });

  test('pairs the brackets of expressions', () => {
    assert.deepEqual(configuration.brackets, [['[', ']']]);
  });

  test('takes a word with its value, a variable, a keyword with its number or prose as one word', () => {
    const text = 'N10 G01X-12.5 T0101 #101=#[#1+2.] IF [#1 GT .5] GOTO10 DO1 ,C1. (HRUBOVÁNÍ)';
    assert.deepEqual(text.match(wordPattern(configuration)), [
      'N10',
      'G01',
      'X-12.5',
      'T0101',
      '#101',
      '#1',
      '2.',
      'IF',
      '#1',
      'GT',
      '.5',
      'GOTO10',
      'DO1',
      'C1.',
      'HRUBOVÁNÍ',
    ]);
  });
});

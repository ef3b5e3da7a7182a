// The packaged extension in a real VS Code: code-server serves the
// workbench on 127.0.0.1, headless Chromium drives it like a user, and the
// checks read what the page shows. run.sh prepares everything this file
// reads from the environment; node 24 runs it as it is (type stripping).

import assert from 'node:assert/strict';
import { type ChildProcess, execFileSync, spawn, spawnSync } from 'node:child_process';
import { promises as fs } from 'node:fs';
import { createServer } from 'node:net';
import * as path from 'node:path';
import { after, before, describe, test } from 'node:test';
import puppeteer, { type Browser, type Frame, type KeyInput, type Page } from 'puppeteer-core';

function env(name: string): string {
  const value = process.env[name];
  assert.ok(value, `run.sh sets ${name}`);
  return value;
}

const CODE_SERVER = env('CODE_SERVER');
const USER_DATA = env('USER_DATA');
const EXTENSIONS = env('EXTENSIONS');
const WORKSPACE = env('WORKSPACE');
const NCC_BIN = env('NCC_BIN');
const DYING_NCC = env('DYING_NCC');
const CHROME = env('CHROME');
const OUT = env('E2E_OUT');

/** How long the workbench, the server or a view may take on a busy machine. */
const WAIT_MS = 90_000;

/** Settings that keep the workbench quiet and offline. */
const QUIET_SETTINGS = {
  'workbench.startupEditor': 'none',
  'workbench.tips.enabled': false,
  'workbench.enableExperiments': false,
  'security.workspace.trust.enabled': false,
  'telemetry.telemetryLevel': 'off',
  'update.mode': 'none',
  'extensions.autoCheckUpdates': false,
  'extensions.autoUpdate': false,
  'chat.disableAIFeatures': true,
  'git.enabled': false,
};

/** The text editor's lines (the Output panel has an editor too). */
const EDITOR_LINES = '.part.editor .monaco-editor .view-lines';

/** A short time as the inlay hints write it: `0.4 ms`, `420 ms`, `4.25 s`, `1:23.4`. */
const TIME = /\d(\.\d+)? m?s\b|\d:\d\d\.\d/;

const sleep = (ms: number) => new Promise((resolve) => setTimeout(resolve, ms));

/**
 * A code-server with `ncc.server.path` in the User settings (not the
 * Machine settings, which a remote window also reads), and a browser
 * page on its workbench.
 */
class Workbench {
  private server: ChildProcess | undefined;
  private browser: Browser | undefined;
  page!: Page;

  async open(serverPath: string): Promise<void> {
    await fs.mkdir(path.join(USER_DATA, 'User'), { recursive: true });
    const settings = { ...QUIET_SETTINGS, 'ncc.server.path': serverPath };
    await fs.writeFile(path.join(USER_DATA, 'User', 'settings.json'), JSON.stringify(settings, null, 2));
    await fs.rm(path.join(USER_DATA, 'Machine', 'settings.json'), { force: true });
    const port = await freePort();
    const log = await fs.open(path.join(OUT, 'logs', `code-server-${path.basename(serverPath)}.log`), 'w');
    // Its own process group, so that closing ends its helpers too.
    this.server = spawn(
      CODE_SERVER,
      [
        '--user-data-dir', USER_DATA,
        '--extensions-dir', EXTENSIONS,
        '--auth', 'none',
        '--bind-addr', `127.0.0.1:${port}`,
        '--disable-telemetry',
        '--disable-update-check',
        '--disable-workspace-trust',
        '--disable-getting-started-override',
        WORKSPACE,
      ],
      { detached: true, stdio: ['ignore', log.fd, log.fd] },
    );
    await log.close();
    const url = `http://127.0.0.1:${port}/?folder=${encodeURIComponent(WORKSPACE)}`;
    await until(async () => (await fetch(`http://127.0.0.1:${port}/healthz`).catch(() => undefined))?.ok, 'code-server');
    this.browser = await puppeteer.launch({
      executablePath: CHROME,
      headless: true,
      // Nothing but loopback resolves: the page reaches only code-server.
      args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--no-proxy-server',
        '--host-resolver-rules=MAP * ~NOTFOUND , EXCLUDE 127.0.0.1'],
      defaultViewport: { width: 1600, height: 1000 },
    });
    this.page = await this.browser.newPage();
    await this.page.goto(url, { waitUntil: 'domcontentloaded', timeout: WAIT_MS });
    await this.waitFor(() => !!document.querySelector('.monaco-workbench .part.statusbar'), 'the workbench');
    // The workbench restores its layout after it shows.
    await sleep(2000);
  }

  async close(): Promise<void> {
    await this.browser?.close();
    if (this.server?.pid !== undefined) {
      process.kill(-this.server.pid, 'SIGTERM');
    }
  }

  /** Waits until `fn`, run in the page with `args`, returns something truthy, and returns it. */
  async waitFor<T, A extends unknown[]>(fn: (...args: A) => T, what: string, ...args: A): Promise<NonNullable<T>> {
    try {
      return await until(() => this.page.evaluate(fn as (...args: unknown[]) => T, ...args).catch(() => undefined), what);
    } catch (error) {
      await this.screenshot(`failed waiting for ${what}`.replace(/[^\w]+/g, '-'));
      throw error;
    }
  }

  async screenshot(name: string): Promise<void> {
    await this.page.screenshot({ path: path.join(OUT, 'screenshots', `${name}.png`) });
  }

  async chord(modifiers: KeyInput[], key: KeyInput): Promise<void> {
    for (const modifier of modifiers) {
      await this.page.keyboard.down(modifier);
    }
    await this.page.keyboard.press(key);
    for (const modifier of [...modifiers].reverse()) {
      await this.page.keyboard.up(modifier);
    }
  }

  /** Opens a file of the workspace by name with Quick Open. */
  async openFile(name: string): Promise<void> {
    await this.chord(['Control'], 'KeyP');
    await this.quickInput(name);
    await this.waitFor((n) => [...document.querySelectorAll('.tab.active')].some((t) => t.textContent?.includes(n)), `the tab of ${name}`, name);
    (await this.page.waitForSelector(EDITOR_LINES, { timeout: WAIT_MS }))?.click();
  }

  /** Runs a command by its title from the Command Palette. */
  async runCommand(title: string): Promise<void> {
    await this.page.keyboard.press('F1');
    await this.quickInput(title);
  }

  /** Types into the focused quick input and takes the row that shows `text`. */
  private async quickInput(text: string): Promise<void> {
    await this.waitFor(() => !!document.querySelector('.quick-input-widget input:focus'), 'the quick input');
    await this.page.keyboard.type(text, { delay: 10 });
    await this.waitFor(
      (t) => [...document.querySelectorAll('.quick-input-list .monaco-list-row')].some((r) => r.textContent?.includes(t)),
      `"${text}" in the quick input`,
      text,
    );
    await this.page.keyboard.press('Enter');
  }
}

/** Polls `probe` until it returns something truthy. */
async function until<T>(probe: () => Promise<T> | T, what: string): Promise<NonNullable<T>> {
  const deadline = Date.now() + WAIT_MS;
  for (;;) {
    const value = await probe();
    if (value) {
      return value as NonNullable<T>;
    }
    if (Date.now() > deadline) {
      throw new Error(`timed out waiting for ${what}`);
    }
    await sleep(300);
  }
}

function freePort(): Promise<number> {
  return new Promise((resolve, reject) => {
    const server = createServer().listen(0, '127.0.0.1', () => {
      const address = server.address();
      server.close(() => (typeof address === 'object' && address ? resolve(address.port) : reject(new Error('no port'))));
    });
  });
}

/** The 1-based line of `file` in the workspace that starts with `start`. */
async function lineOf(file: string, start: string): Promise<number> {
  const lines = (await fs.readFile(path.join(WORKSPACE, file), 'utf8')).split('\n');
  const index = lines.findIndex((line) => line.startsWith(start));
  assert.ok(index >= 0, `${file} has a line ${start}`);
  return index + 1;
}

describe('the packaged extension in code-server', () => {
  const workbench = new Workbench();

  before(() => workbench.open(NCC_BIN));
  after(() => workbench.close());

  test('a diagnostic of ncc check shows in the Problems panel', async () => {
    // ncc check exits with 1 on the error it reports.
    const check = spawnSync(NCC_BIN, ['check', '--format', 'json', path.join(WORKSPACE, 'milling', 'error.NCP')], {
      encoding: 'utf8',
    });
    const [finding] = JSON.parse(check.stdout) as { message: string; code: string }[];
    assert.ok(finding, 'ncc check reports error.NCP');
    await workbench.openFile('error.NCP');
    await workbench.waitFor(() => document.querySelectorAll('.view-overlays [class*="squiggly-error"]').length, 'a squiggle');
    await workbench.chord(['Control', 'Shift'], 'KeyM');
    const problems = await workbench.waitFor(
      (message) => {
        const panel = document.querySelector<HTMLElement>('.markers-panel');
        return panel?.innerText.includes(message) ? panel.innerText : '';
      },
      'the diagnostic in the Problems panel',
      finding.message,
    );
    await workbench.screenshot('1-problems');
    assert.match(problems, /error\.NCP/);
    assert.ok(problems.includes(finding.code), problems);
  });

  test('hover on a code shows its documentation', async () => {
    // The heading `ncc explain` gives the code: `### G90 — Absolute dimensions`.
    const heading = execFileSync(NCC_BIN, ['explain', 'G90'], { encoding: 'utf8' }).split('\n')[0].replace(/^#+\s*/, '');
    await workbench.openFile('pocket.NCP');
    // The mouse rests on G90 in `N10 G90 …`, as a user's would.
    const hover = await hoverOn(workbench, 'G90', 'N10', heading);
    await workbench.screenshot('2-hover');
    await workbench.page.mouse.move(0, 0);
    assert.ok(hover.includes(heading), hover);
  });

  test("a block's time shows at the end of its last line with words, not after its comment lines", async () => {
    // N60 ZR11 is followed by three comment lines of its block.
    const lines = await workbench.waitFor(
      (time, editorLines) => {
        // Top to bottom, with the inlay hints in their text.
        const lines = [...document.querySelectorAll<HTMLElement>(`${editorLines} .view-line`)]
          .sort((a, b) => parseFloat(a.style.top) - parseFloat(b.style.top))
          // The editor draws spaces as no-break spaces.
          .map((line) => line.innerText.replace(/\u00a0/g, ' '));
        const n60 = lines.findIndex((line) => line.startsWith('N60 ZR11'));
        return n60 >= 0 && new RegExp(time).test(lines[n60]) ? lines.slice(n60, n60 + 5) : undefined;
      },
      'the time hint of N60',
      TIME.source,
      EDITOR_LINES,
    );
    await workbench.screenshot('3-inlay-hints');
    const [n60, ...after] = lines;
    assert.match(n60, new RegExp(`^N60 ZR11.*(${TIME.source})`), n60);
    for (const line of after.slice(0, 3)) {
      assert.match(line, /^"/, 'the comment lines of N60 follow it');
      assert.doesNotMatch(line, TIME, `no time after the comment line ${line}`);
    }
    assert.match(after[3], /^N70 .*/);
  });

  test('ncc: Show Toolpath opens a view with the SVG of the moves', async () => {
    const rapid = await lineOf('milling/pocket.NCP', 'N40 G00 X60. Y40.');
    await workbench.runCommand('ncc: Show Toolpath');
    // The view is a webview: a frame in a frame, whose origin is its own.
    const [moves, view] = await until(async () => {
      for (const frame of workbench.page.frames()) {
        const lines = await svgMoveLines(frame);
        if (lines && lines.length > 0) {
          return [lines, frame] as const;
        }
      }
      return undefined;
    }, 'the toolpath view with its moves');
    await sleep(1000);
    await workbench.screenshot('4-toolpath');
    assert.ok(moves.length > 20, `the pocket has many moves: ${moves.length}`);
    assert.ok(moves.includes(rapid), `the rapid move of line ${rapid} is drawn`);
    // The wheel zooms in about the pointer: the picture's box narrows.
    const [before, after] = await view.evaluate(() => {
      const svg = document.querySelector('#plot svg');
      const plot = document.getElementById('plot');
      if (svg === null || plot === null) {
        return [null, null];
      }
      const box = svg.getAttribute('viewBox');
      const rect = svg.getBoundingClientRect();
      const at = { clientX: rect.left + rect.width / 2, clientY: rect.top + rect.height / 3 };
      plot.dispatchEvent(new WheelEvent('wheel', { deltaY: -100, bubbles: true, cancelable: true, ...at }));
      return [box, svg.getAttribute('viewBox')];
    });
    const width = (box: string | null) => Number((box ?? '').split(' ')[2]);
    assert.ok(width(after) < width(before), `the wheel zooms in: ${before} → ${after}`);
    await sleep(500);
    await workbench.screenshot('4b-toolpath-zoomed');
  });

  test('a Haas lathe program opens in its language, and no request about it fails', async () => {
    await workbench.openFile('O1000.nc');
    // The language's name in the status bar, once the editor shows the file.
    await workbench.waitFor(
      () => document.querySelector<HTMLElement>('.part.statusbar')?.innerText.includes('Haas lathe'),
      'Haas lathe in the status bar',
    );
    // The server answers what the workbench asks on opening (diagnostics,
    // folding, symbols, semantic tokens, the cycle time's code lens).
    await sleep(3000);
    await workbench.screenshot('5-haas');
    const toasts = await workbench.page.evaluate(() =>
      [...document.querySelectorAll<HTMLElement>('.notification-toast')].map((t) => t.innerText),
    );
    assert.deepEqual(
      toasts.filter((toast) => /failed|is not open/.test(toast)),
      [],
      'no notification about the requests on O1000.nc',
    );
  });

  test('a Sinumerik program gets its syntax error, and no error notification', async () => {
    const note = '`(` is not closed by `)` on its line';
    await workbench.openFile('MAIN.MPF');
    // The mouse rests on the text, so that the workbench asks for a hover
    // too, besides what it asks for on opening (folding, symbols, tokens).
    const word = await workbench.page.evaluate((editorLines) => {
      const token = document.querySelector<HTMLElement>(`${editorLines} .view-line span span`);
      const box = token?.getBoundingClientRect();
      return box ? { x: box.x + box.width / 2, y: box.y + box.height / 2 } : undefined;
    }, EDITOR_LINES);
    assert.ok(word, 'a word in the editor');
    await workbench.page.mouse.move(word.x, word.y, { steps: 4 });
    const shown = await workbench.page.evaluate(() => !!document.querySelector<HTMLElement>('.markers-panel')?.offsetParent);
    if (!shown) {
      await workbench.chord(['Control', 'Shift'], 'KeyM');
    }
    const problems = await workbench.waitFor(
      (text) => {
        const panel = document.querySelector<HTMLElement>('.markers-panel');
        return panel?.innerText.includes(text) ? panel.innerText : '';
      },
      'the syntax error in the Problems panel',
      note,
    );
    await sleep(3000);
    await workbench.screenshot('6-sinumerik');
    await workbench.page.mouse.move(0, 0);
    assert.match(problems, /MAIN\.MPF/);
    // The language's name in the status bar.
    const status = await workbench.page.evaluate(() => document.querySelector<HTMLElement>('.part.statusbar')?.innerText ?? '');
    assert.match(status, /Siemens Sinumerik/);
    const toasts = await workbench.page.evaluate(() =>
      [...document.querySelectorAll<HTMLElement>('.notification-toast')].map((t) => t.innerText),
    );
    // The language client's notice of a failed request ("Request
    // textDocument/semanticTokens/full failed. Message: …"): the server
    // answers every request about MAIN.MPF.
    const failures = toasts.filter((toast) => /failed|is not open/.test(toast));
    assert.deepEqual(failures, [], 'no notification about the requests on MAIN.MPF');
  });
});

/**
 * Rests the mouse on the word `word` of the first editor line that starts
 * with `line`, as a user's would, until a hover shows `text`; it moves
 * there again while the lines still move (the code lens above them comes
 * with the estimate).
 */
async function hoverOn(workbench: Workbench, word: string, line: string, text: string): Promise<string> {
  let attempt = 0;
  return until(async () => {
    const box = await workbench.page.evaluate(
      (editorLines, word, line) => {
        const tokens = document.querySelectorAll<HTMLElement>(`${editorLines} .view-line span span`);
        const token = [...tokens].find(
          (t) => t.innerText.trim() === word && t.closest('.view-line')?.textContent?.startsWith(line),
        );
        const box = token?.getBoundingClientRect();
        return box ? { x: box.x + box.width / 2, y: box.y + box.height / 2 } : undefined;
      },
      EDITOR_LINES,
      word,
      line,
    );
    if (box) {
      attempt += 1;
      await workbench.page.mouse.move(box.x + (attempt % 3) - 1, box.y, { steps: 4 });
      await sleep(1500);
    }
    return workbench.page.evaluate(
      (text) =>
        [...document.querySelectorAll<HTMLElement>('.monaco-hover')]
          .map((h) => (h.offsetParent ? h.innerText : ''))
          .find((t) => t.includes(text)),
      text,
    );
  }, `the hover with ${text}`);
}

/** The source lines of the moves drawn in an SVG of `frame`, if it has one. */
function svgMoveLines(frame: Frame): Promise<number[] | undefined> {
  return frame
    .evaluate(() => {
      const paths = document.querySelectorAll('svg path[data-line]');
      return paths.length > 0 ? [...paths].map((p) => Number(p.getAttribute('data-line'))) : undefined;
    })
    .catch(() => undefined);
}

// A second session: the workbench now knows the extension's settings from
// the start, so a setting that a remote window keeps out of the User
// settings (scope machine or machine-overridable) would never reach the
// extension here, which would then find no ncc at all.
describe('a server that exits as it starts', () => {
  const workbench = new Workbench();

  before(() => workbench.open(DYING_NCC));
  after(() => workbench.close());

  test('is reported in a notification with its reason and a button to the log', async () => {
    const reason = 'the machine file /nowhere/machine.toml cannot be read';
    await workbench.openFile('pocket.NCP');
    const toast = await workbench.waitFor(
      (text) =>
        [...document.querySelectorAll<HTMLElement>('.notification-toast')].map((t) => t.innerText).find((t) => t.includes(text)),
      'the notification',
      reason,
    );
    await workbench.screenshot('7-start-failure');
    assert.match(toast, /exited as it started/);
    assert.match(toast, /Show Log/);
    // The client's own notification would cover this one and its button.
    const toasts = await workbench.page.evaluate(() =>
      [...document.querySelectorAll<HTMLElement>('.notification-toast')].map((t) => t.innerText),
    );
    assert.deepEqual(toasts, [toast], 'one notification reports the failed start');
    const status = await workbench.page.evaluate(() => document.querySelector<HTMLElement>('.part.statusbar')?.innerText ?? '');
    assert.match(status, /\bncc\b/);
    const [showLog] = await workbench.page.$$('xpath/.//*[contains(@class, "notification-toast")]//*[contains(@class, "monaco-button") and normalize-space(.)="Show Log"]');
    assert.ok(showLog, 'the notification has the button Show Log');
    await showLog.click();
    await workbench.waitFor(
      // The log is an editor, which draws spaces as no-break spaces.
      (text) => document.querySelector<HTMLElement>('.part.panel')?.innerText.replace(/\u00a0/g, ' ').includes(text),
      'the reason in the log',
      reason,
    );
    await workbench.screenshot('8-log');
  });
});

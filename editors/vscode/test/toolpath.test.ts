// The toolpath view's logic (src/toolpath.ts): the line a click means, the
// messages between the page and the extension, the page's
// Content-Security-Policy, the answers of `ncc.plot` and the render schedule.

import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import * as path from 'node:path';
import { describe, test } from 'node:test';
import {
  clock,
  LATHE_VIEWS,
  MAX_ZOOM,
  MILL_VIEWS,
  panned,
  parseViewBox,
  pictureAt,
  viewBoxText,
  zoomed,
  type ElementLike,
  failureMessage,
  highlightSelector,
  nonceOf,
  pageHtml,
  panelTitle,
  parseFromView,
  parsePlotted,
  plotArguments,
  plotMessage,
  RenderSchedule,
  revealOf,
  revealTarget,
  sourceFiles,
  type Timers,
  VIEW_SCRIPT,
} from '../src/toolpath';

const root = path.resolve(__dirname, '..', '..');

/** A stand-in for a DOM element: its attributes and its parent. */
function element(attributes: Record<string, string>, parent: ElementLike | null = null): ElementLike {
  return { getAttribute: (name) => attributes[name] ?? null, parentElement: parent };
}

/** The lines of `ncc plot` this test plays with: a move of line 3, a stop mark of a macrocycle file. */
const SVG = [
  '<svg xmlns="http://www.w3.org/2000/svg" width="1000" height="400">',
  '<rect width="100%" height="100%" fill="white"/>',
  '<path data-line="3" d="M20 20 L40 40" fill="none" stroke="#3b4cc0"><title>line 3: 600 mm/min</title></path>',
  '<circle data-line="7" data-file="/p/L9001 &amp; co" cx="1" cy="2" r="3"><title>line 7</title></circle>',
  '</svg>',
].join('\n');

describe('a click in the picture', () => {
  const svg = element({});
  const move = element({ 'data-line': '3' }, svg);
  const tooltip = element({}, move);

  test('on a move, or on its tooltip inside it, reveals the move’s line', () => {
    assert.deepEqual(revealOf(move), { type: 'reveal', line: 3 });
    assert.deepEqual(revealOf(tooltip), { type: 'reveal', line: 3 });
  });

  test('on a move of another file names the file', () => {
    const mark = element({ 'data-line': '7', 'data-file': '/p/L9001' }, svg);
    assert.deepEqual(revealOf(mark), { type: 'reveal', line: 7, file: '/p/L9001' });
  });

  test('on the background, the legend or nothing reveals nothing', () => {
    assert.equal(revealOf(element({ fill: 'white' }, svg)), undefined);
    assert.equal(revealOf(null), undefined);
  });

  test('on a line that is not a line number reveals nothing', () => {
    for (const line of ['0', '-1', '1.5', '1e3', 'x', '', '99999999999999999999']) {
      assert.equal(revealOf(element({ 'data-line': line }, svg)), undefined, line);
    }
  });
});

describe('messages from the page', () => {
  test('a reveal and ready pass', () => {
    assert.deepEqual(parseFromView({ type: 'reveal', line: 12 }), { type: 'reveal', line: 12 });
    assert.deepEqual(parseFromView({ type: 'reveal', line: 2, file: '/p/L1' }), {
      type: 'reveal',
      line: 2,
      file: '/p/L1',
    });
    assert.deepEqual(parseFromView({ type: 'ready' }), { type: 'ready' });
    assert.deepEqual(parseFromView({ type: 'view', view: 'radius' }), { type: 'view', view: 'radius' });
    assert.deepEqual(parseFromView({ type: 'view', view: 'diameter' }), { type: 'view', view: 'diameter' });
    assert.deepEqual(parseFromView({ type: 'view', view: 'iso' }), { type: 'view', view: 'iso' });
    assert.deepEqual(parseFromView({ type: 'view', view: 'top' }), { type: 'view', view: 'top' });
  });

  test('anything else is dropped', () => {
    const bad = [
      null,
      undefined,
      'reveal',
      12,
      [],
      {},
      { type: 'reveal' },
      { type: 'reveal', line: '12' },
      { type: 'reveal', line: 0 },
      { type: 'reveal', line: 1.5 },
      { type: 'reveal', line: Number.NaN },
      { type: 'reveal', line: 3, file: 42 },
      { type: 'reveal', line: 3, file: '' },
      { type: 'open', line: 3 },
      { type: 'view' },
      { type: 'view', view: 'Radius' },
      { type: 'view', view: 'side' },
    ];
    for (const message of bad) {
      assert.equal(parseFromView(message), undefined, JSON.stringify(message));
    }
  });
});

describe('the line a reveal selects', () => {
  const files = sourceFiles(SVG);

  test('is the document’s line counted from 0', () => {
    assert.deepEqual(revealTarget({ type: 'reveal', line: 3 }, 10, files), { file: undefined, line: 2 });
    assert.deepEqual(revealTarget({ type: 'reveal', line: 1 }, 10, files), { file: undefined, line: 0 });
  });

  test('is the last line when the picture is older than an edit that removed lines', () => {
    assert.deepEqual(revealTarget({ type: 'reveal', line: 30 }, 10, files), { file: undefined, line: 9 });
  });

  test('is in another file only if the picture names it', () => {
    assert.deepEqual([...files], ['/p/L9001 & co']);
    assert.deepEqual(revealTarget({ type: 'reveal', line: 7, file: '/p/L9001 & co' }, 10, files), {
      file: '/p/L9001 & co',
      line: 6,
    });
    assert.equal(revealTarget({ type: 'reveal', line: 7, file: '/etc/passwd' }, 10, files), undefined);
  });
});

test('the highlight selects the document’s line, not a macrocycle file’s line of that number', () => {
  assert.equal(highlightSelector(7), '[data-line="7"]:not([data-file])');
});

describe('the page', () => {
  const nonce = nonceOf(new Uint8Array(16).fill(171));
  const html = pageHtml({
    nonce,
    scriptUri: 'https://file+.vscode-resource.vscode-cdn.net/ext/dist/toolpath.js?a=1&b="2"',
    title: 'Toolpath: <P1>.NCP',
  });
  const policy = /<meta http-equiv="Content-Security-Policy" content="([^"]*)">/.exec(html)?.[1] ?? '';

  test('has a policy that runs only what has the nonce', () => {
    const directives = new Map(
      policy.split(';').map((directive) => {
        const [name, ...values] = directive.trim().split(/\s+/);
        return [name, values] as const;
      }),
    );
    assert.deepEqual(directives.get('default-src'), ["'none'"]);
    assert.deepEqual(directives.get('script-src'), [`'nonce-${nonce}'`]);
    assert.deepEqual(directives.get('style-src'), [`'nonce-${nonce}'`]);
    assert.doesNotMatch(policy, /unsafe|https?:|\*/);
  });

  test('gives the nonce to its script and its style, and has no other script', () => {
    const scripts = html.match(/<script\b[^>]*>/g) ?? [];
    assert.equal(scripts.length, 1);
    assert.match(scripts[0] ?? '', new RegExp(`nonce="${nonce}"`));
    assert.match(html, new RegExp(`<style nonce="${nonce}">`));
    assert.doesNotMatch(html, /\son[a-z]+=/i, 'no inline event handlers');
  });

  test('escapes what it is given', () => {
    assert.match(html, /src="[^"]*\?a=1&amp;b=&quot;2&quot;"/);
    assert.match(html, /<title>Toolpath: &lt;P1&gt;\.NCP<\/title>/);
  });

  test('nonces are 128 random bits as hex', () => {
    assert.equal(nonce, 'ab'.repeat(16));
    assert.notEqual(nonceOf(crypto.getRandomValues(new Uint8Array(16))), nonceOf(new Uint8Array(16)));
  });

  test('offers a lathe’s two views and a mill’s two, each hidden until a picture of its kind comes', () => {
    assert.match(html, /<fieldset id="lathe-views" class="views" hidden>/);
    assert.match(html, /<fieldset id="mill-views" class="views" hidden>/);
    const values = [...html.matchAll(/<input type="radio" name="view" value="([a-z]+)">/g)].map((match) => match[1]);
    assert.deepEqual(values, [...LATHE_VIEWS, ...MILL_VIEWS]);
  });

  test('loads the script the bundler writes and the package ships', () => {
    const esbuild = readFileSync(path.join(root, 'esbuild.mjs'), 'utf8');
    assert.match(esbuild, new RegExp(`outfile: 'dist/${VIEW_SCRIPT}'`));
    const ignore = readFileSync(path.join(root, '.vscodeignore'), 'utf8').split('\n');
    assert.ok(ignore.includes(`!dist/${VIEW_SCRIPT}`), 'the package keeps the page script');
  });
});

describe('the answer of ncc.plot', () => {
  const answer = {
    svg: SVG,
    totalTimeS: 83.4567,
    findings: [
      { line: 4, message: 'the executor does not run G08 yet', stopped: false },
      { file: '/p/L9001', line: 2, message: 'G36: refused', stopped: true },
      { nonsense: true },
    ],
  };

  test('becomes the page’s picture with the total time and the findings', () => {
    const plotted = parsePlotted(answer);
    assert.ok(plotted);
    assert.deepEqual(plotMessage(plotted), {
      type: 'plot',
      svg: SVG,
      summary: 'Total time 0:01:23.457',
      notes: ['line 4: the executor does not run G08 yet', 'L9001 line 2: G36: refused'],
      view: null,
    });
  });

  test('says which lathe view it drew, and nothing off a lathe or for a view it does not know', () => {
    assert.equal(parsePlotted({ ...answer, view: 'radius' })?.view, 'radius');
    assert.deepEqual(plotMessage({ ...answer, findings: [], view: 'diameter' }), {
      type: 'plot',
      svg: SVG,
      summary: 'Total time 0:01:23.457',
      notes: [],
      view: 'diameter',
    });
    for (const view of [null, undefined, 'mirrored', 2]) {
      assert.equal(parsePlotted({ ...answer, view })?.view, null, String(view));
    }
  });

  test('asks for the view chosen, else leaves the default to the server', () => {
    assert.deepEqual(plotArguments('file:///O1000.nc', undefined), ['file:///O1000.nc']);
    assert.deepEqual(plotArguments('file:///O1000.nc', 'radius'), ['file:///O1000.nc', { view: 'radius' }]);
  });

  test('without a picture is no answer', () => {
    for (const value of [null, 'svg', {}, { svg: SVG }, { svg: 1, totalTimeS: 2 }, { svg: SVG, totalTimeS: Infinity }]) {
      assert.equal(parsePlotted(value), undefined, JSON.stringify(value));
    }
  });

  test('an error shows its message, with the picture of a run that stopped', () => {
    // vscode-jsonrpc's ResponseError is an Error with `code` and `data`.
    const stopped = Object.assign(new Error('the run stopped at line 4: G03: no arc'), { code: -32803, data: answer });
    assert.deepEqual(failureMessage(stopped), {
      type: 'error',
      message: 'the run stopped at line 4: G03: no arc',
      svg: SVG,
      notes: ['line 4: the executor does not run G08 yet'],
      view: null,
    });
    const notOpen = Object.assign(new Error('ncc.plot: file:///x.NCP is not open'), { code: -32602 });
    assert.deepEqual(failureMessage(notOpen), { type: 'error', message: notOpen.message, notes: [] });
    assert.equal(failureMessage('no server').message, 'no server');
  });

  test('titles the panel with the file and the time', () => {
    assert.equal(panelTitle('P1.NCP'), 'Toolpath: P1.NCP');
    assert.equal(panelTitle('P1.NCP', 3725.5), 'Toolpath: P1.NCP · 1:02:05.500');
  });

  test('times read as ncc run writes them', () => {
    assert.equal(clock(0), '0:00:00.000');
    assert.equal(clock(-1), '0:00:00.000');
    assert.equal(clock(59.9999), '0:01:00.000', 'rounded before it is split');
    assert.equal(clock(61.25), '0:01:01.250');
  });
});

/** Timers that run when the test says. */
class FakeTimers implements Timers {
  now = 0;
  private pending: { at: number; callback: () => void; id: number }[] = [];
  private next = 0;

  set(callback: () => void, ms: number): unknown {
    const id = this.next++;
    this.pending.push({ at: this.now + ms, callback, id });
    return id;
  }

  clear(handle: unknown): void {
    this.pending = this.pending.filter((timer) => timer.id !== handle);
  }

  get count(): number {
    return this.pending.length;
  }

  advance(ms: number): void {
    this.now += ms;
    const due = this.pending.filter((timer) => timer.at <= this.now);
    this.pending = this.pending.filter((timer) => timer.at > this.now);
    due.forEach((timer) => timer.callback());
  }
}

/** Lets the promises that are ready run. */
const settle = () => new Promise((resolve) => setImmediate(resolve));

describe('the render schedule', () => {
  test('draws once the typing has rested for the delay', async () => {
    const timers = new FakeTimers();
    let renders = 0;
    const schedule = new RenderSchedule(async () => void renders++, 500, timers);
    schedule.soon();
    timers.advance(300);
    schedule.soon();
    timers.advance(300);
    schedule.soon();
    assert.equal(timers.count, 1);
    await settle();
    assert.equal(renders, 0, 'nothing while typing');
    timers.advance(500);
    await settle();
    assert.equal(renders, 1);
  });

  test('draws at once on now(), and a request during a render follows it once', async () => {
    const timers = new FakeTimers();
    const finish: (() => void)[] = [];
    let renders = 0;
    const schedule = new RenderSchedule(
      () => {
        renders++;
        return new Promise<void>((resolve) => finish.push(resolve));
      },
      500,
      timers,
    );
    const first = schedule.now();
    assert.equal(renders, 1);
    void schedule.now();
    void schedule.now();
    await settle();
    assert.equal(renders, 1, 'one render at a time');
    finish.shift()?.();
    await settle();
    assert.equal(renders, 2, 'the requests during the render make one more');
    finish.shift()?.();
    await first;
    assert.equal(renders, 2);
  });

  test('goes on after a failed render, and stops when disposed', async () => {
    const timers = new FakeTimers();
    let renders = 0;
    const schedule = new RenderSchedule(
      async () => {
        renders++;
        throw new Error('server gone');
      },
      500,
      timers,
    );
    await schedule.now();
    await schedule.now();
    assert.equal(renders, 2);
    schedule.soon();
    schedule.dispose();
    assert.equal(timers.count, 0);
    await schedule.now();
    assert.equal(renders, 2);
  });
});

describe('the command in the manifest', () => {
  const manifest = JSON.parse(readFileSync(path.join(root, 'package.json'), 'utf8'));

  test('is ncc: Show Toolpath, in the editor title and the palette for CNC8x6 and Haas lathe', () => {
    const command = manifest.contributes.commands.find((c: { command: string }) => c.command === 'ncc.showToolpath');
    assert.equal(`${command?.category}: ${command?.title}`, 'ncc: Show Toolpath');
    const title = manifest.contributes.menus['editor/title'].find(
      (m: { command: string }) => m.command === 'ncc.showToolpath',
    );
    assert.equal(title?.when, 'resourceLangId == cnc8x6 || resourceLangId == haas-lathe');
    assert.equal(title?.group, 'navigation');
    const palette = manifest.contributes.menus.commandPalette.find(
      (m: { command: string }) => m.command === 'ncc.showToolpath',
    );
    assert.equal(palette?.when, 'editorLangId == cnc8x6 || editorLangId == haas-lathe');
  });
});

describe('zooming and panning the picture', () => {
  const whole = { x: 0, y: 0, width: 1000, height: 800 };

  test('reads and writes viewBox attributes, refusing what is no box', () => {
    assert.deepEqual(parseViewBox('0 0 1000 800'), whole);
    assert.deepEqual(parseViewBox(' 1,2, 3 4'), { x: 1, y: 2, width: 3, height: 4 });
    for (const bad of [null, '', '0 0 1000', '0 0 0 800', '0 0 -1 800', 'a b c d', '0 0 1000 800 5']) {
      assert.equal(parseViewBox(bad), undefined, String(bad));
    }
    assert.equal(viewBoxText({ x: 1 / 3, y: 0, width: 250, height: 200 }), '0.333 0 250 200');
  });

  test('a zoom keeps the point under the pointer where it is', () => {
    const at = { x: 250, y: 200 };
    const closer = zoomed(whole, 2, at, whole);
    assert.deepEqual(closer, { x: 125, y: 100, width: 500, height: 400 });
    // The point's share of the box is the same before and after.
    assert.equal((at.x - closer.x) / closer.width, (at.x - whole.x) / whole.width);
    assert.deepEqual(zoomed(closer, 0.5, at, whole), whole);
  });

  test('a zoom stops at the whole picture and at the closest zoom', () => {
    assert.deepEqual(zoomed(whole, 0.5, { x: 500, y: 400 }, whole), whole);
    let box = whole;
    for (let i = 0; i < 100; i++) {
      box = zoomed(box, 2, { x: 500, y: 400 }, whole);
    }
    assert.equal(box.width, whole.width / MAX_ZOOM);
    assert.equal(box.height, whole.height / MAX_ZOOM);
  });

  test('a pan moves the picture with the pointer, in the picture’s units', () => {
    const half = { x: 100, y: 100, width: 500, height: 400 };
    // 500 units over 1000 screen pixels: a drag of 100 pixels is 50 units.
    assert.deepEqual(panned(half, 100, -40, 1000), { x: 50, y: 120, width: 500, height: 400 });
  });

  test('the pointer’s place on the screen is a point of the shown box', () => {
    const rect = { left: 10, top: 20, width: 500, height: 400 };
    assert.deepEqual(pictureAt(whole, rect, 260, 220), { x: 500, y: 400 });
    assert.deepEqual(pictureAt({ x: 100, y: 50, width: 100, height: 80 }, rect, 10, 20), { x: 100, y: 50 });
  });
});

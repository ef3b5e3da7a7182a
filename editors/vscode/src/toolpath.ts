// The toolpath view's logic, free of `vscode` and of the DOM, so that node
// tests run it: the page and its Content-Security-Policy, the messages
// between the page and the extension, the line a click means, the answers
// of the server's `ncc.plot` command and when to ask for them again.
//
// A lathe's picture comes in the radius or the diameter view, a mill's in
// the plane or an isometric view (`ncc plot --view`); the page offers the
// choices of the kind the server says it drew. The page zooms (the wheel,
// about the pointer) and pans (a drag) by the picture's viewBox; a double
// click shows the whole picture again.
//
// The picture is the SVG of `ncc plot`, pure data: every move and mark
// carries `data-line` (its line, from 1) and, when a macrocycle file or the
// cycle file made it, `data-file` (that file's path). The page's script
// (webview/main.ts) adds the clicks and the highlight.

/** The server's command that draws a document's current text. */
export const PLOT_COMMAND = 'ncc.plot';

/** The page's script, as the bundler writes it to `dist/`. */
export const VIEW_SCRIPT = 'toolpath.js';

/** How long the document must rest before the picture is drawn again. */
export const RENDER_DELAY_MS = 500;

/**
 * How a picture shows the program: a lathe's machined half or whole profile
 * labelled with diameters, a mill's plane or its three axes in an isometric view.
 */
export type PlotView = 'radius' | 'diameter' | 'top' | 'iso';

/** The views of a lathe's picture, and of a mill's. */
export const LATHE_VIEWS: readonly PlotView[] = ['diameter', 'radius'];
export const MILL_VIEWS: readonly PlotView[] = ['top', 'iso'];

/** The answer of `ncc.plot`. */
export interface Plotted {
  svg: string;
  /** Seconds, with the control's velocity model. */
  totalTimeS: number;
  findings: Finding[];
  /** The view drawn; `null` when the server did not say. */
  view: PlotView | null;
}

/** The arguments of `ncc.plot`: the document, and the view once one was chosen (else the server's default). */
export function plotArguments(uri: string, view: PlotView | undefined): unknown[] {
  return view === undefined ? [uri] : [uri, { view }];
}

export function isPlotView(value: unknown): value is PlotView {
  return value === 'radius' || value === 'diameter' || value === 'top' || value === 'iso';
}

/** What the run did not run, or where it stopped. */
export interface Finding {
  /** Another file than the document's (a macrocycle file). */
  file?: string;
  /** Counted from 1. */
  line: number;
  message: string;
  stopped: boolean;
}

/** Messages from the extension to the page. */
export type ToView =
  | { type: 'plot'; svg: string; summary: string; notes: string[]; view: PlotView | null }
  | { type: 'error'; message: string; svg?: string; notes: string[]; view?: PlotView | null }
  | { type: 'highlight'; line: number | null };

/** Messages from the page to the extension. */
export type FromView = { type: 'ready' } | Reveal | { type: 'view'; view: PlotView };

/** A click on a move or mark: show its line. */
export interface Reveal {
  type: 'reveal';
  /** Counted from 1, as `data-line`. */
  line: number;
  /** The `data-file` of the element: a file other than the document. */
  file?: string;
}

/** What the click target needs to offer: DOM elements, SVG ones included, do. */
export interface ElementLike {
  getAttribute(name: string): string | null;
  readonly parentElement: ElementLike | null;
}

/**
 * The message a click on `target` posts: the nearest element, from the
 * target up, with a `data-line`. Nothing outside the moves and marks (the
 * legend, the background).
 */
export function revealOf(target: ElementLike | null): Reveal | undefined {
  for (let element = target; element; element = element.parentElement) {
    const line = element.getAttribute('data-line');
    if (line === null) {
      continue;
    }
    const parsed = parseLine(line);
    if (parsed === undefined) {
      return undefined;
    }
    const file = element.getAttribute('data-file');
    return file === null ? { type: 'reveal', line: parsed } : { type: 'reveal', line: parsed, file };
  }
  return undefined;
}

function parseLine(text: string): number | undefined {
  if (!/^[1-9][0-9]*$/.test(text)) {
    return undefined;
  }
  const line = Number(text);
  return Number.isSafeInteger(line) ? line : undefined;
}

/** A message from the page, checked: the page is another process, and its data is not trusted. */
export function parseFromView(message: unknown): FromView | undefined {
  if (typeof message !== 'object' || message === null) {
    return undefined;
  }
  const { type, line, file, view } = message as Record<string, unknown>;
  if (type === 'ready') {
    return { type: 'ready' };
  }
  if (type === 'view') {
    return isPlotView(view) ? { type: 'view', view } : undefined;
  }
  if (type !== 'reveal' || typeof line !== 'number' || !Number.isSafeInteger(line) || line < 1) {
    return undefined;
  }
  if (file === undefined) {
    return { type: 'reveal', line };
  }
  return typeof file === 'string' && file !== '' ? { type: 'reveal', line, file } : undefined;
}

/** Where a reveal goes: a file (`undefined`: the plotted document) and a line counted from 0. */
export interface Target {
  file: string | undefined;
  line: number;
}

/**
 * The line to select for `reveal`. The plotted document's lines are known
 * (`lineCount`), and a line past its end (the picture is older than an edit)
 * is its last. Another file must be one the picture names: the page may
 * only open the files the run read.
 */
export function revealTarget(reveal: Reveal, lineCount: number, files: ReadonlySet<string>): Target | undefined {
  if (reveal.file !== undefined) {
    return files.has(reveal.file) ? { file: reveal.file, line: reveal.line - 1 } : undefined;
  }
  if (lineCount < 1) {
    return undefined;
  }
  return { file: undefined, line: Math.min(reveal.line, lineCount) - 1 };
}

/** The files other than the document that `svg` names (`data-file`). */
export function sourceFiles(svg: string): Set<string> {
  const files = new Set<string>();
  for (const match of svg.matchAll(/\sdata-file="([^"]*)"/g)) {
    files.add(unescapeXml(match[1] ?? ''));
  }
  return files;
}

function unescapeXml(text: string): string {
  return text.replace(/&(lt|gt|quot|apos|amp);/g, (_, name: string) =>
    name === 'lt' ? '<' : name === 'gt' ? '>' : name === 'quot' ? '"' : name === 'apos' ? "'" : '&',
  );
}

/**
 * The selector of the moves and marks of line `line` (from 1) of the
 * plotted document: those of other files have a `data-file`.
 */
export function highlightSelector(line: number): string {
  return `[data-line="${Math.trunc(line)}"]:not([data-file])`;
}

/** `h:mm:ss.sss`, as `ncc run` and the picture's legend write a time. */
export function clock(seconds: number): string {
  // Whole milliseconds first, so that 59.9999 s is 0:01:00.000.
  const ms = Math.round(Math.max(0, seconds) * 1000);
  const hours = Math.floor(ms / 3_600_000);
  const minutes = Math.floor((ms % 3_600_000) / 60_000);
  const rest = ((ms % 60_000) / 1000).toFixed(3).padStart(6, '0');
  return `${hours}:${String(minutes).padStart(2, '0')}:${rest}`;
}

/** The panel's title: the file's name, and the total time once known. */
export function panelTitle(fileName: string, totalTimeS?: number): string {
  return totalTimeS === undefined ? `Toolpath: ${fileName}` : `Toolpath: ${fileName} · ${clock(totalTimeS)}`;
}

/** The answer of `ncc.plot`, checked. */
export function parsePlotted(value: unknown): Plotted | undefined {
  if (typeof value !== 'object' || value === null) {
    return undefined;
  }
  const { svg, totalTimeS, findings, view } = value as Record<string, unknown>;
  if (typeof svg !== 'string' || typeof totalTimeS !== 'number' || !Number.isFinite(totalTimeS)) {
    return undefined;
  }
  const checked: Finding[] = [];
  for (const finding of Array.isArray(findings) ? findings : []) {
    const { file, line, message, stopped } = (finding ?? {}) as Record<string, unknown>;
    if (typeof line === 'number' && typeof message === 'string') {
      const base = { line, message, stopped: stopped === true };
      checked.push(typeof file === 'string' ? { ...base, file } : base);
    }
  }
  return { svg, totalTimeS, findings: checked, view: isPlotView(view) ? view : null };
}

/** A finding as the page lists it: `line 12: …`, or `L9001 line 3: …` in another file. */
export function noteOf(finding: Finding): string {
  const place = finding.file === undefined ? `line ${finding.line}` : `${baseName(finding.file)} line ${finding.line}`;
  return `${place}: ${finding.message}`;
}

function baseName(path: string): string {
  return path.split(/[\\/]/).pop() ?? path;
}

/** The page's message for an answer of `ncc.plot`. */
export function plotMessage(plotted: Plotted): ToView {
  return {
    type: 'plot',
    svg: plotted.svg,
    summary: `Total time ${clock(plotted.totalTimeS)}`,
    notes: plotted.findings.map(noteOf),
    view: plotted.view,
  };
}

/**
 * The page's message for a failed `ncc.plot`: the error's message, and the
 * picture of the run up to where it stopped when the server sent one (a
 * JSON-RPC error's `data`).
 */
export function failureMessage(error: unknown): ToView & { type: 'error' } {
  const message =
    error instanceof Error ? error.message : typeof error === 'string' ? error : 'ncc.plot failed without a message';
  const data = typeof error === 'object' && error !== null ? (error as { data?: unknown }).data : undefined;
  const partial = parsePlotted(data);
  if (partial === undefined) {
    return { type: 'error', message, notes: [] };
  }
  return {
    type: 'error',
    message,
    svg: partial.svg,
    notes: partial.findings.filter((f) => !f.stopped).map(noteOf),
    view: partial.view,
  };
}

/** The part of the picture shown: an SVG `viewBox`, in the picture's units. */
export interface ViewBox {
  x: number;
  y: number;
  width: number;
  height: number;
}

/** A `viewBox` attribute's box, if it is four numbers and a size. */
export function parseViewBox(text: string | null): ViewBox | undefined {
  const numbers = (text ?? '').trim().split(/[\s,]+/).map(Number);
  if (numbers.length !== 4 || !numbers.every(Number.isFinite) || numbers[2] <= 0 || numbers[3] <= 0) {
    return undefined;
  }
  const [x, y, width, height] = numbers;
  return { x, y, width, height };
}

export function viewBoxText(box: ViewBox): string {
  return [box.x, box.y, box.width, box.height].map((n) => Number(n.toFixed(3))).join(' ');
}

/** The closest a zoom goes: a thousandth of the picture's width. */
export const MAX_ZOOM = 1000;

/**
 * `box` zoomed by `factor` (above 1: closer) about the point `at` of the
 * picture, which stays where it is on the screen; never wider than the
 * whole picture `whole`, nor narrower than its width over {@link MAX_ZOOM}.
 */
export function zoomed(box: ViewBox, factor: number, at: { x: number; y: number }, whole: ViewBox): ViewBox {
  const width = Math.min(Math.max(box.width / factor, whole.width / MAX_ZOOM), whole.width);
  const scale = width / box.width;
  return {
    x: at.x - (at.x - box.x) * scale,
    y: at.y - (at.y - box.y) * scale,
    width,
    height: box.height * scale,
  };
}

/** `box` moved with a drag of `dx`, `dy` screen pixels over a picture `screenWidth` pixels wide. */
export function panned(box: ViewBox, dx: number, dy: number, screenWidth: number): ViewBox {
  const units = box.width / screenWidth;
  return { ...box, x: box.x - dx * units, y: box.y - dy * units };
}

/** The point of the picture under screen point (`clientX`, `clientY`) of a picture shown in `rect`. */
export function pictureAt(
  box: ViewBox,
  rect: { left: number; top: number; width: number; height: number },
  clientX: number,
  clientY: number,
): { x: number; y: number } {
  return {
    x: box.x + ((clientX - rect.left) / rect.width) * box.width,
    y: box.y + ((clientY - rect.top) / rect.height) * box.height,
  };
}

/** A nonce for the page's Content-Security-Policy, from random bytes (16 or more): their hex digits. */
export function nonceOf(bytes: Uint8Array): string {
  return Array.from(bytes, (byte) => byte.toString(16).padStart(2, '0')).join('');
}

export interface PageOptions {
  /** The nonce of this page's script and style. */
  nonce: string;
  /** The script's address in the webview (`asWebviewUri`). */
  scriptUri: string;
  title: string;
}

/**
 * The page: nothing loads but the script and the style with the nonce; no
 * remote content, no inline handlers, no `eval`. The picture comes later by
 * message, and the script inserts it as parsed SVG.
 */
export function pageHtml({ nonce, scriptUri, title }: PageOptions): string {
  const policy = [
    "default-src 'none'",
    `style-src 'nonce-${nonce}'`,
    `script-src 'nonce-${nonce}'`,
    'img-src data:',
    "base-uri 'none'",
    "form-action 'none'",
  ].join('; ');
  return `<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="UTF-8">
<meta http-equiv="Content-Security-Policy" content="${escapeHtml(policy)}">
<meta name="viewport" content="width=device-width, initial-scale=1.0">
<title>${escapeHtml(title)}</title>
<style nonce="${escapeHtml(nonce)}">${PAGE_STYLE}</style>
</head>
<body>
<header><span id="summary">Drawing…</span>
<fieldset id="lathe-views" class="views" hidden><legend>X as</legend>
<label><input type="radio" name="view" value="diameter"> diameter (whole profile)</label>
<label><input type="radio" name="view" value="radius"> radius (machined half)</label>
</fieldset>
<fieldset id="mill-views" class="views" hidden><legend>View</legend>
<label><input type="radio" name="view" value="top"> plane</label>
<label><input type="radio" name="view" value="iso"> 3D (isometric)</label>
</fieldset>
<span id="hint">wheel: zoom · drag: pan · double click: whole picture</span></header>
<div id="error" role="alert" hidden></div>
<ul id="notes"></ul>
<main id="plot"></main>
<script nonce="${escapeHtml(nonce)}" src="${escapeHtml(scriptUri)}"></script>
</body>
</html>
`;
}

const PAGE_STYLE = `
body { padding: 0 12px; color: var(--vscode-foreground); font-family: var(--vscode-font-family); }
header { padding: 6px 0; display: flex; gap: 16px; align-items: center; flex-wrap: wrap; }
.views { display: flex; gap: 10px; border: none; margin: 0; padding: 0; }
.views[hidden] { display: none; }
.views legend { float: left; padding: 0; margin-right: 4px; }
#hint { color: var(--vscode-descriptionForeground); }
#error { padding: 6px 8px; margin-bottom: 6px; border: 1px solid var(--vscode-inputValidation-errorBorder, #be1100);
  background: var(--vscode-inputValidation-errorBackground, #5a1d1d); white-space: pre-wrap; }
#notes { margin: 0 0 6px; padding-left: 18px; color: var(--vscode-descriptionForeground); }
#plot svg { width: 100%; height: auto; display: block; touch-action: none; }
#plot.dragging { cursor: grabbing; }
#plot [data-line] { cursor: pointer; }
#plot path[data-line]:hover { stroke-width: 3; }
#plot path.selected { stroke: #e000e0; stroke-width: 4; }
#plot circle.selected { stroke: #e000e0; stroke-width: 2; }
.stale #plot { opacity: 0.5; }
`;

function escapeHtml(text: string): string {
  return text.replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;').replace(/"/g, '&quot;');
}

/** Timers, given to the schedule so that tests can drive them. */
export interface Timers {
  set(callback: () => void, ms: number): unknown;
  clear(handle: unknown): void;
}

const realTimers: Timers = {
  set: (callback, ms) => setTimeout(callback, ms),
  clear: (handle) => clearTimeout(handle as ReturnType<typeof setTimeout>),
};

/**
 * When to draw: `soon()` after the document has rested for the delay,
 * `now()` at once (a save, the first picture). One render at a time: one
 * asked for while another runs follows it, so answers never arrive out of
 * order and a slow program is not run again for every keystroke.
 */
export class RenderSchedule {
  private timer: unknown;
  private running = false;
  private again = false;
  private disposed = false;

  constructor(
    private readonly render: () => Promise<void>,
    private readonly delayMs: number = RENDER_DELAY_MS,
    private readonly timers: Timers = realTimers,
  ) {}

  soon(): void {
    this.cancelTimer();
    if (!this.disposed) {
      this.timer = this.timers.set(() => {
        this.timer = undefined;
        void this.fire();
      }, this.delayMs);
    }
  }

  now(): Promise<void> {
    this.cancelTimer();
    return this.fire();
  }

  dispose(): void {
    this.disposed = true;
    this.cancelTimer();
  }

  private cancelTimer(): void {
    if (this.timer !== undefined) {
      this.timers.clear(this.timer);
      this.timer = undefined;
    }
  }

  private async fire(): Promise<void> {
    if (this.disposed) {
      return;
    }
    if (this.running) {
      this.again = true;
      return;
    }
    this.running = true;
    try {
      await this.render();
    } catch {
      // The render reports its own failures; the schedule goes on.
    } finally {
      this.running = false;
    }
    if (this.again) {
      this.again = false;
      await this.fire();
    }
  }
}

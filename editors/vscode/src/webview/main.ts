// The toolpath view's page script. It runs in the webview, under the page's
// Content-Security-Policy: it shows the picture the extension sends, posts a
// click on a move or mark as the line to reveal, highlights the moves and
// marks of the line the cursor is on, and zooms and pans the picture. The
// decisions are in ../toolpath.ts, where node tests run them.

import {
  type FromView,
  highlightSelector,
  isPlotView,
  LATHE_VIEWS,
  MILL_VIEWS,
  panned,
  parseViewBox,
  pictureAt,
  type PlotView,
  revealOf,
  type ToView,
  type ViewBox,
  viewBoxText,
  zoomed,
} from '../toolpath';

declare function acquireVsCodeApi(): { postMessage(message: FromView): void };

const vscode = acquireVsCodeApi();

function element(id: string): HTMLElement {
  const found = document.getElementById(id);
  if (found === null) {
    throw new Error(`the page has no #${id}`);
  }
  return found;
}

const plot = element('plot');
const summary = element('summary');
const error = element('error');
const notes = element('notes');
const latheViews = element('lathe-views');
const millViews = element('mill-views');

/** The whole picture's box, and the part shown when zoomed or panned. */
let whole: ViewBox | undefined;
let shown: ViewBox | undefined;

/** The document's line the cursor is on, from 1. */
let highlighted: number | null = null;

/** Replaces the picture with `svg`, parsed as SVG: it is never run as HTML. */
function showPicture(svg: string): boolean {
  const parsed = new DOMParser().parseFromString(svg, 'image/svg+xml');
  const root = parsed.documentElement;
  if (root.localName !== 'svg' || parsed.getElementsByTagName('parsererror').length > 0) {
    return false;
  }
  // The picture is data; nothing in it may run or load.
  for (const active of Array.from(root.querySelectorAll('script, foreignObject'))) {
    active.remove();
  }
  // A redrawn picture of the same frame keeps the part shown.
  const box = parseViewBox(root.getAttribute('viewBox'));
  const same = box !== undefined && whole !== undefined && viewBoxText(box) === viewBoxText(whole);
  whole = box;
  if (!same) {
    shown = undefined;
  }
  if (shown !== undefined) {
    root.setAttribute('viewBox', viewBoxText(shown));
  }
  plot.replaceChildren(document.importNode(root, true));
  highlight(highlighted);
  return true;
}

function picture(): SVGSVGElement | null {
  return plot.querySelector('svg');
}

function show(box: ViewBox): void {
  shown = box;
  picture()?.setAttribute('viewBox', viewBoxText(box));
}

function showNotes(list: string[]): void {
  notes.replaceChildren(
    ...list.map((text) => {
      const item = document.createElement('li');
      item.textContent = text;
      return item;
    }),
  );
}

function showError(message: string | undefined): void {
  error.hidden = message === undefined;
  error.textContent = message ?? '';
}

/** Offers the views of the kind of `view` (a lathe's, a mill's), `view` chosen; none when unknown (`null`). */
function showView(view: PlotView | null): void {
  latheViews.hidden = view === null || !LATHE_VIEWS.includes(view);
  millViews.hidden = view === null || !MILL_VIEWS.includes(view);
  for (const input of Array.from(document.querySelectorAll<HTMLInputElement>('.views input'))) {
    input.checked = input.value === view;
  }
}

function highlight(line: number | null): void {
  for (const old of Array.from(plot.querySelectorAll('.selected'))) {
    old.classList.remove('selected');
  }
  highlighted = line;
  if (line !== null) {
    for (const mark of Array.from(plot.querySelectorAll(highlightSelector(line)))) {
      mark.classList.add('selected');
    }
  }
}

window.addEventListener('message', (event: MessageEvent<ToView>) => {
  const message = event.data;
  switch (message.type) {
    case 'plot':
      if (showPicture(message.svg)) {
        summary.textContent = message.summary;
        showError(undefined);
        showView(message.view);
        document.body.classList.remove('stale');
      } else {
        showError('The server sent a picture that is not SVG.');
      }
      showNotes(message.notes);
      break;
    case 'error':
      showError(message.message);
      showNotes(message.notes);
      if (message.svg !== undefined && showPicture(message.svg)) {
        summary.textContent = 'The run up to where it stopped';
        showView(message.view ?? null);
        document.body.classList.remove('stale');
      } else {
        // The last picture stays, faded: it no longer shows the text.
        document.body.classList.add('stale');
      }
      break;
    case 'highlight':
      highlight(message.line);
      break;
  }
});

/** A drag in progress: where the pointer was, and whether it moved enough to be no click. */
let drag: { x: number; y: number; moved: boolean } | undefined;
/** The last drag moved the picture: the click that ends it reveals nothing. */
let dragged = false;

plot.addEventListener('click', (event) => {
  if (dragged) {
    dragged = false;
    return;
  }
  const reveal = revealOf(event.target instanceof Element ? event.target : null);
  if (reveal !== undefined) {
    vscode.postMessage(reveal);
  }
});

plot.addEventListener(
  'wheel',
  (event) => {
    const svg = picture();
    const box = shown ?? whole;
    if (svg === null || box === undefined || whole === undefined) {
      return;
    }
    event.preventDefault();
    const at = pictureAt(box, svg.getBoundingClientRect(), event.clientX, event.clientY);
    show(zoomed(box, event.deltaY < 0 ? 1.25 : 1 / 1.25, at, whole));
  },
  { passive: false },
);

plot.addEventListener('pointerdown', (event) => {
  if (event.button === 0) {
    drag = { x: event.clientX, y: event.clientY, moved: false };
  }
});

plot.addEventListener('pointermove', (event) => {
  const svg = picture();
  const box = shown ?? whole;
  if (drag === undefined || svg === null || box === undefined) {
    return;
  }
  const [dx, dy] = [event.clientX - drag.x, event.clientY - drag.y];
  if (!drag.moved && Math.hypot(dx, dy) < 4) {
    return;
  }
  if (!drag.moved) {
    drag.moved = true;
    plot.setPointerCapture(event.pointerId);
    plot.classList.add('dragging');
  }
  show(panned(box, dx, dy, svg.getBoundingClientRect().width));
  drag.x = event.clientX;
  drag.y = event.clientY;
});

function endDrag(): void {
  dragged = drag?.moved ?? false;
  drag = undefined;
  plot.classList.remove('dragging');
}
plot.addEventListener('pointerup', endDrag);
plot.addEventListener('pointercancel', endDrag);

plot.addEventListener('dblclick', () => {
  if (whole !== undefined) {
    show(whole);
  }
});

document.addEventListener('change', (event) => {
  const value = event.target instanceof HTMLInputElement ? event.target.value : undefined;
  if (isPlotView(value)) {
    vscode.postMessage({ type: 'view', view: value });
  }
});

vscode.postMessage({ type: 'ready' });

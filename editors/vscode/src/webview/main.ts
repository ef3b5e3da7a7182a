// The toolpath view's page script. It runs in the webview, under the page's
// Content-Security-Policy: it shows the picture the extension sends, posts a
// click on a move or mark as the line to reveal, and highlights the moves
// and marks of the line the cursor is on. The decisions are in
// ../toolpath.ts, where node tests run them.

import { type FromView, highlightSelector, type LatheView, revealOf, type ToView } from '../toolpath';

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
const views = element('views');

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
  plot.replaceChildren(document.importNode(root, true));
  highlight(highlighted);
  return true;
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

/** Offers the lathe's views, `view` chosen; none off a lathe (`null`). */
function showView(view: LatheView | null): void {
  views.hidden = view === null;
  for (const input of Array.from(views.querySelectorAll('input'))) {
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

plot.addEventListener('click', (event) => {
  const reveal = revealOf(event.target instanceof Element ? event.target : null);
  if (reveal !== undefined) {
    vscode.postMessage(reveal);
  }
});

views.addEventListener('change', (event) => {
  const value = event.target instanceof HTMLInputElement ? event.target.value : undefined;
  if (value === 'radius' || value === 'diameter') {
    vscode.postMessage({ type: 'view', view: value });
  }
});

vscode.postMessage({ type: 'ready' });

/**
 * The demo by keyboard alone: Escape stops whatever runs (recording, playback, animating); on the face's canvas the
 * arrow keys orbit and + / - zoom (as its label says), Space plays or pauses and , / . step a frame; Enter works where
 * the browser gives only Space (the file input behind "Open an audio file", the checkboxes).
 */
import { ui } from './controls';

export interface KeyActions {
  /** Escape: stop recording, playback or animating; true if something was stopped. */
  escape(): boolean;
  /** Whether a take is loaded (Space and , / . need one). */
  hasTake(): boolean;
  togglePlay(): void;
  step(delta: number): void;
  orbit(azimuth: number, polar: number): void;
  zoom(factor: number): void;
}

/** Radians per arrow key press, and the zoom factor per + press. */
const ORBIT_STEP = Math.PI / 24;
const ZOOM_STEP = 0.85;

export function bindKeys(a: KeyActions): void {
  document.addEventListener('keydown', (ev) => {
    if (ev.key === 'Escape' && !ev.defaultPrevented && a.escape()) ev.preventDefault();
  });
  ui.canvas.addEventListener('keydown', (ev) => {
    if (ev.ctrlKey || ev.metaKey || ev.altKey) return;
    const orbit: Record<string, [number, number]> = {
      ArrowLeft: [ORBIT_STEP, 0], ArrowRight: [-ORBIT_STEP, 0], ArrowUp: [0, ORBIT_STEP], ArrowDown: [0, -ORBIT_STEP],
    };
    const zoom: Record<string, number> = { '+': ZOOM_STEP, '=': ZOOM_STEP, '-': 1 / ZOOM_STEP, _: 1 / ZOOM_STEP };
    if (ev.key in orbit) a.orbit(...orbit[ev.key]);
    else if (ev.key in zoom) a.zoom(zoom[ev.key]);
    else if (ev.key === ' ' && a.hasTake()) a.togglePlay();
    else if ((ev.key === ',' || ev.key === '.') && a.hasTake()) a.step(ev.key === '.' ? 1 : -1);
    else return;
    ev.preventDefault();
  });
  // A file input opens its chooser on Space only; Enter should too. Checkboxes likewise toggle on Space only.
  ui.fileInput.addEventListener('keydown', (ev) => {
    if (ev.key !== 'Enter') return;
    ev.preventDefault();
    ui.fileInput.click();
  });
  for (const box of [ui.loopCheck, ui.arrowsCheck, ui.sideCheck]) {
    box.addEventListener('keydown', (ev) => {
      if (ev.key !== 'Enter') return;
      ev.preventDefault();
      box.click();
    });
  }
}

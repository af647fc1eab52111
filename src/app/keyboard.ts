/**
 * The demo by keyboard alone: Escape stops whatever runs (recording, playback, animating); on the face's canvas the
 * arrow keys orbit and + / - zoom (as its label says), Space plays or pauses and , / . step a frame; Enter works where
 * the browser gives only Space (the file input behind "Open an audio file", the checkboxes).
 */
import { ui } from './controls';
import { cameraKey, type Orbitable } from '../render/camera-keys';

export interface KeyActions {
  /** Escape: stop recording, playback or animating; true if something was stopped. */
  escape(): boolean;
  /** Whether a take is loaded (Space and , / . need one). */
  hasTake(): boolean;
  togglePlay(): void;
  step(delta: number): void;
  /** The view the arrow keys and + / - move the camera of. */
  view(): Orbitable | null;
}

export function bindKeys(a: KeyActions): void {
  document.addEventListener('keydown', (ev) => {
    if (ev.key === 'Escape' && !ev.defaultPrevented && a.escape()) ev.preventDefault();
  });
  ui.canvas.addEventListener('keydown', (ev) => {
    if (ev.ctrlKey || ev.metaKey || ev.altKey || cameraKey(ev, a.view())) return;
    if (ev.key === ' ' && a.hasTake()) {
      if (!ev.repeat) a.togglePlay(); // held down: toggled once, not at every repeat
    } else if ((ev.key === ',' || ev.key === '.') && a.hasTake()) a.step(ev.key === '.' ? 1 : -1);
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

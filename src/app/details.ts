/**
 * What the Details disclosure under the status line says (issue 18): the technical side of what the status line
 * tells in plain words. The face and the GPU adapter, the model and its decoder, and each take's figures and notes.
 */
import type { FaceTemplate } from '../template/face-template';
import type { WebGPUSupport } from '../gpu/capabilities';
import type { Backend, TalkingFaceEngine } from '../engine/engine';
import { tell, ui } from './controls';
import { isolated } from './names';
import { fmaModule, simdUnavailable } from '../attention/simd-kernel';
import { SHORT_CLIP_SECONDS } from '../player/audio-notes';
import { levels, SILENT_PEAK } from '../audio/decode';
import type { Take } from './take-view';

export function setupDetails(face: FaceTemplate, gpu: WebGPUSupport): string {
  return `Face: ${face.id} (${face.vertexCount} vertices). ` +
    (gpu.available ? `WebGPU adapter: ${gpu.description}.` : `WebGPU: none (${gpu.description}); the CPU path will be used.`);
}

/** The decoder's line: which one, why, and the CPU decoder's arithmetic and threads. */
export function decoderDetails(e: TalkingFaceEngine): string {
  const simd = `WebAssembly SIMD${fmaModule() ? ', fused multiply-add' : ''}`;
  const kernel = e.cpuKernel === 'wasm-simd' ? simd : `JavaScript (no SIMD: ${simdUnavailable || 'unavailable'})`;
  return `Decoder: ${e.backend} (${e.backendReason}; CPU decoder: ${kernel} on ${e.cpuThreads} thread${e.cpuThreads > 1 ? 's' : ''}).`;
}

/**
 * A take's figures (no speed figure for a very short clip: its few frames measure start-up, not speed; nor for a
 * silent one, which the model is not run on: engine.animateSpeech; nor for a recording whose live frames were kept
 * with some held, which were not all computed) and notes.
 */
export function takeDetails(t: Take, notes: string[]): string {
  const speed = levels(t.samples).peak < SILENT_PEAK ? 'not run on silent audio' : t.seconds < SHORT_CLIP_SECONDS
    ? 'no speed figure for a clip this short' : t.heldFrames
    ? `no speed figure: the live frames were kept, ${t.heldFrames} of them held where the device fell behind`
    : `${(t.computeMs / t.animation.frames).toFixed(1)} ms per frame, ${(t.seconds / (t.computeMs / 1000)).toFixed(1)}x real time`;
  return `${isolated(t.name)}: ${t.animation.frames} frames. Decoder ${t.backend}: ${speed}.` + (notes.length ? ` Notes: ${notes.join('; ')}.` : '');
}

let switches = 0;

/**
 * Decode on `want` from now on (a clip being animated switches at its next chunk): say so, and keep the details'
 * decoder line up to date. A choice overtaken by a later one (WebGPU still being set up) says nothing.
 */
export function switchBackend(engine: TalkingFaceEngine, want: Backend): void {
  const chosen = ui.backendSelect.value;
  const call = ++switches;
  engine.setBackend(want).then(
    () => {
      if (call !== switches) return;
      ui.backendSelect.dataset.chosen = chosen; // what the list goes back to if a later choice fails
      tell(`Decoding on the ${engine.backend === 'cpu' ? 'CPU' : 'WebGPU'} decoder from now on (a clip being animated switches at its next chunk).`);
      ui.setupInfo.textContent = ui.setupInfo.textContent!.replace(/Decoder: .*$/, decoderDetails(engine));
    },
    (err: Error) => {
      if (call !== switches) return;
      ui.backendSelect.value = ui.backendSelect.dataset.chosen ?? 'auto'; // the list says what decodes: still the one before
      tell(`Cannot use ${want}: ${err.message}`, true);
    },
  );
}

/**
 * The opened details lie over the top right of the face's view, as a video player's statistics do, instead of over
 * the controls (which they covered until closed): placed when opened and as the page resizes or scrolls. Escape
 * closes them while the focus is on them.
 */
export function bindDetailsPanel(): void {
  const margin = 8;
  const place = (): void => {
    if (!ui.details.open) return;
    const stage = ui.stage.getBoundingClientRect();
    const top = Math.max(margin, stage.top + margin);
    const style = ui.detailsBody.style;
    style.top = `${top}px`;
    style.right = `${Math.max(margin, document.documentElement.clientWidth - stage.right + margin)}px`;
    style.width = `${Math.min(stage.width - 2 * margin, Math.max(18 * 16, 0.42 * stage.width))}px`;
    style.maxHeight = `${Math.max(6 * 16, stage.bottom - top - margin)}px`;
  };
  ui.details.addEventListener('toggle', place);
  addEventListener('resize', place);
  addEventListener('scroll', place, { passive: true });
  ui.details.addEventListener('keydown', (ev) => {
    if (ev.key !== 'Escape' || !ui.details.open) return;
    ui.details.open = false;
    ui.details.querySelector('summary')!.focus();
    ev.preventDefault(); // handled: the page's Escape (stop what runs) does not also act
  });
}

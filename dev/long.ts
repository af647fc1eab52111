/**
 * Test page (dev/long.html, loaded by tests/e2e/long-clip.spec.ts): ten minutes of audio animated
 * offline with keep: false, frames handed to onFrames chunk by chunk. The JS heap is sampled (after a
 * forced GC, Chromium's --js-flags=--expose-gc) as the clip goes, to show memory does not grow with
 * the clip's length. Not part of the app.
 */
import { checkManifest, DEFAULT_MANIFEST_URL } from '../src/model/manifest';
import { parseSafetensors, f32 } from '../src/model/safetensors';
import { TalkingFaceEngine } from '../src/engine/engine';

interface MemoryPerformance {
  memory?: { usedJSHeapSize: number };
}

function heap(): number {
  // Twice: a full GC finishes the previous one's sweeping of dead ArrayBuffers' memory (concurrent in V8),
  // so the figure is the live heap, not the chunk outputs that are garbage but not yet swept.
  (globalThis as unknown as { gc?: () => void }).gc?.();
  (globalThis as unknown as { gc?: () => void }).gc?.();
  return (performance as unknown as MemoryPerformance).memory?.usedJSHeapSize ?? NaN;
}

async function main() {
  const minutes = Number(new URLSearchParams(location.search).get('minutes') ?? '10');
  const manifest = checkManifest(await (await fetch(DEFAULT_MANIFEST_URL)).json());
  const fx = parseSafetensors(await (await fetch(`/models/${manifest.fixtures.file}`)).arrayBuffer()).tensors;
  const speech = f32(fx, 'audio');
  const engine = await TalkingFaceEngine.load({ backend: 'cpu' });
  const rate = manifest.audio.sample_rate;
  // The fixture's speech, tiled with a varying gain and short pauses, to the length asked for.
  const samples = new Float32Array(Math.round(minutes * 60 * rate));
  for (let o = 0, k = 0; o < samples.length; k++) {
    const gain = 0.5 + 0.5 * Math.abs(Math.sin(k));
    const n = Math.min(speech.length, samples.length - o);
    for (let i = 0; i < n; i++) samples[o + i] = speech[i] * gain;
    o += n + Math.round(rate * 0.1 * (k % 4));
  }
  const heapAt: { frame: number; bytes: number }[] = [];
  let frames = 0;
  let checksum = 0;
  const t0 = performance.now();
  const before = heap();
  const result = await engine.animate(samples, {
    keep: false,
    chunkFrames: 96,
    onFrames: (first, vertices) => {
      frames += vertices.length / (engine.template.vertexCount * 3);
      checksum += vertices[0];
      if (heapAt.length === 0 || first - heapAt[heapAt.length - 1].frame >= 1500) heapAt.push({ frame: first, bytes: heap() });
    },
  });
  const after = heap();
  return {
    seconds: samples.length / rate,
    frames,
    expectedFrames: result.frames,
    keptVertices: result.vertices.length,
    checksumFinite: Number.isFinite(checksum),
    heapBefore: before,
    heapAfter: after,
    heapAt,
    outputBytesIfKept: result.frames * engine.template.vertexCount * 3 * 4,
    wallSeconds: (performance.now() - t0) / 1000,
  };
}

main().then(
  (r) => {
    Object.assign(globalThis, { longResult: r });
    document.getElementById('status')!.textContent = 'done';
  },
  (e: Error) => {
    Object.assign(globalThis, { longResult: { error: `${e.name}: ${e.message}` } });
    document.getElementById('status')!.textContent = `failed: ${e.message}`;
  },
);

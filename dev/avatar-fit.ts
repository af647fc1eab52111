/**
 * `npm run avatar-fit` page (dev/avatar-fit.html, driven by scripts/avatar-fit.ts): the engine animates a clip with
 * its blend-shape output on, in headless Chromium, and hands back the predicted frames, the ARKit weights and
 * visemes, and what the avatar stage cost; and checks that streaming the clip gives the same weights. The fit is
 * measured by the script. Not part of the app.
 */
import { TalkingFaceEngine } from '../src/engine/engine';
import { joinFrames, type Frames } from '../src/engine/frames';

const status = document.getElementById('status')!;

/** Little-endian float32 bytes as base64: a compact way out of page.evaluate. */
function base64(a: Float32Array): string {
  const bytes = new Uint8Array(a.buffer, a.byteOffset, a.byteLength);
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

const engine = await TalkingFaceEngine.load({ backend: 'cpu' });
const basisMs = (() => {
  const t = performance.now();
  void engine.avatarWeights; // the basis and the solver's Gram matrix, built once
  return performance.now() - t;
})();

Object.assign(globalThis, {
  avatarFit: {
    info: () => ({ basisMs, userAgent: navigator.userAgent, cpuKernel: engine.cpuKernel, cpuThreads: engine.cpuThreads }),
    async clip(samples: number[]) {
      const x = Float32Array.from(samples);
      const plain = await engine.animate(x, { unposed: true }); // without the avatar stage: its frames must not change
      engine.resetTimes();
      const a = await engine.animate(x, { unposed: true, blendshapes: true });
      const stageMs = { ...engine.times };
      let same = 0;
      for (let i = 0; i < a.unposed!.length; i++) same = Math.max(same, Math.abs(a.unposed![i] - plain.unposed![i]));
      const b = a.blendshapes!;
      // The same clip streamed in 40 ms pieces: the weights must equal the offline ones.
      const chunks: Frames[] = [];
      const stream = engine.createStream((_first, frames) => chunks.push(frames), { blendshapes: true });
      const piece = Math.round(engine.manifest.audio.sample_rate * 0.04);
      for (let i = 0; i < x.length; i += piece) await stream.push(x.subarray(i, i + piece));
      await stream.end();
      const streamed = joinFrames(chunks, a.fps).blendshapes!;
      let streamChange = 0;
      for (let i = 0; i < b.arkit.length; i++) streamChange = Math.max(streamChange, Math.abs(b.arkit[i] - streamed.arkit[i]));
      return {
        frames: a.frames, unposed: base64(a.unposed!), arkit: base64(b.arkit), visemes: base64(b.visemes),
        headRotation: base64(b.headRotation), pose: base64(a.pose), stageMs, unposedChange: same, streamChange,
      };
    },
  },
});
status.textContent = 'Ready.';

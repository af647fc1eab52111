/**
 * Test page (dev/live.html, loaded by tests/e2e/live.spec.ts): the microphone (Chromium's fake device
 * playing a WAV) -> AudioWorklet capture -> streaming engine, for `?seconds=` seconds. Reports what
 * came out: frames, measured latency, the inner-lip gap per frame, and whether the streamed frames
 * equal the offline animation of the captured take. Not part of the app.
 */
import { TalkingFaceEngine } from '../src/engine/engine';
import { openMicrophone } from '../src/audio/capture';
import { innerLipGaps } from '../src/template/lip-gap';

function lipGaps(unposed: Float32Array, count: number, n: number, upper: Uint32Array, lower: Uint32Array): number[] {
  // Mean vertical distance between the inner-lip contours, per frame (template units).
  const gaps: number[] = [];
  for (let f = 0; f < count; f++) {
    let u = 0, l = 0;
    for (const v of upper) u += unposed[(f * n + v) * 3 + 1];
    for (const v of lower) l += unposed[(f * n + v) * 3 + 1];
    gaps.push(u / upper.length - l / lower.length);
  }
  return gaps;
}

async function main() {
  const params = new URLSearchParams(location.search);
  const seconds = Number(params.get('seconds') ?? '3');
  const engine = await TalkingFaceEngine.load({ backend: 'cpu' });
  const n = engine.template.vertexCount;
  const { lips_inner_upper: upper, lips_inner_lower: lower } = engine.template.regions;
  const streamed: Float32Array[] = [];
  const poses: number[] = [];
  const gaps: number[] = [];
  const contour: number[] = [];
  const media = await openMicrophone();
  const live = await engine.listen(media, (_, frames) => {
    streamed.push(frames.vertices.slice());
    poses.push(...frames.pose);
    gaps.push(...lipGaps(frames.unposed, frames.count, n, upper, lower));
    contour.push(...innerLipGaps(frames.unposed, frames.count, n, upper, lower));
  }, { maxLagFrames: Infinity }); // every frame, so the stream can be compared with the offline animation
  await new Promise((r) => setTimeout(r, seconds * 1000));
  const latency = live.stream.latency;
  const take = await live.stop();
  const offline = await engine.animate(take);
  const all = new Float32Array(streamed.reduce((s, a) => s + a.length, 0));
  let o = 0;
  for (const a of streamed) {
    all.set(a, o);
    o += a.length;
  }
  let diff = 0;
  for (let i = 0; i < all.length; i++) diff = Math.max(diff, Math.abs(all[i] - offline.vertices[i]));
  const peak = take.reduce((m, v) => Math.max(m, Math.abs(v)), 0);
  // ?head=1: the streamed head rotation (degrees, frames x 3), and the same take with the pose head's mean pose alone.
  const degrees = (pose: ArrayLike<number>) => Array.from({ length: pose.length / 6 * 3 }, (_, i) => (pose[6 * Math.floor(i / 3) + (i % 3)] * 180) / Math.PI);
  let meanHead: number[] | undefined;
  if (params.get('head')) {
    engine.headMotionSeed = null;
    meanHead = degrees((await engine.animate(take)).pose);
  }
  return {
    capturedSeconds: take.length / engine.manifest.audio.sample_rate,
    peak,
    frames: all.length / (n * 3),
    offlineFrames: offline.frames,
    streamVsOffline: diff,
    latency,
    lookAheadMs: live.stream.lookAheadMs,
    tracksEnded: media.getTracks().every((t) => t.readyState === 'ended'),
    mmPerUnit: 1 / engine.unitsPerMm,
    gaps,
    contourGaps: contour,
    // ?take=1: the captured samples too, so a test can find where in the played file the take began.
    take: params.get('take') ? Array.from(take) : undefined,
    head: params.get('head') ? degrees(poses) : undefined,
    meanHead,
    hasHeadMotion: engine.hasHeadMotion,
  };
}

main().then(
  (r) => {
    Object.assign(globalThis, { liveResult: r });
    document.getElementById('status')!.textContent = 'done';
  },
  (e: Error) => {
    Object.assign(globalThis, { liveResult: { error: `${e.name}: ${e.message}` } });
    document.getElementById('status')!.textContent = `failed: ${e.message}`;
  },
);

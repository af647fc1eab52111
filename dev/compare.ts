/**
 * `npm run compare` page (dev/compare.html, driven by scripts/compare.ts): this project's engine and the peer
 * lip-sync libraries run on the same audio in the same headless Chromium, each as its authors ship it.
 * - HeadAudio (@met4citizen/headaudio, MIT): its Processor (what its AudioWorklet wraps) fed 128-sample blocks
 *   at 16 kHz with its shipped English model; its viseme events (ids: aa E I O U PP SS TH DD FF kk nn RR CH sil).
 * - wlipsync (MIT, after uLipSync): its WASM (dist/wlipsync.wasm) driven as its AudioWorklet processor drives it
 *   (dist/audio-processor.js): a ring buffer, execute() every block; calibrated as uLipSync is, by recording
 *   MFCC snapshots of each vowel (here: vowels of the corpus's train split, read from the WASM's own mfccOut).
 * Returns per-system outputs and compute times; the measures are computed by scripts/compare.ts.
 * Not part of the app.
 */
import { TalkingFaceEngine } from '../src/engine/engine';
import { innerLipGaps } from '../src/template/lip-gap';
// @ts-expect-error: plain ESM without types, imported as its worklet imports it.
import { Processor } from '@met4citizen/headaudio/modules/processor.mjs';
// @ts-expect-error: as above.
import { Training } from '@met4citizen/headaudio/modules/training.mjs';
import headAudioModelUrl from '@met4citizen/headaudio/dist/model-en-mixed.bin?url';
import wlipsyncWasmUrl from 'wlipsync/wlipsync.wasm?url';

/** The uLipSync profile layout wlipsync reads (its dist/types/types.d.ts). */
interface Profile {
  targetSampleRate: number; sampleCount: number; melFilterBankChannels: number; compareMethod: number;
  mfccNum: number; mfccDataCount: number; useStandardization: boolean;
  mfccs: { name: string; mfccCalibrationDataList: { array: number[] }[] }[];
}

interface WlExports {
  load_profile(...a: number[]): number; precompute_profile(): void; set_input(sr: number): void;
  get_input_buffer(): number; get_input_buffer_size(): number; get_volume_ptr(): number; execute(index: number): number;
  mfccOut: WebAssembly.Global;
}

/** One wlipsync instance, fed as its worklet feeds it: samples into its ring, execute() every `block` samples. */
async function wlipsync(module: WebAssembly.Module, profile: Profile, sampleRate: number) {
  const memory = new WebAssembly.Memory({ initial: 4 });
  const z = (await WebAssembly.instantiate(module, { env: { memory } })).exports as unknown as WlExports;
  const E = profile.mfccs.length;
  const raw = z.load_profile(profile.targetSampleRate, profile.sampleCount, profile.melFilterBankChannels, profile.compareMethod,
    E, profile.mfccDataCount, profile.useStandardization ? 1 : 0);
  const view = new DataView(memory.buffer, raw, E * profile.mfccDataCount * 12 * 4);
  let o = 0;
  for (const m of profile.mfccs) for (const d of m.mfccCalibrationDataList) for (const v of d.array) { view.setFloat32(o, v, true); o += 4; }
  z.precompute_profile();
  z.set_input(sampleRate);
  const ring = new Float32Array(memory.buffer, z.get_input_buffer(), z.get_input_buffer_size());
  const volume = new DataView(memory.buffer, z.get_volume_ptr(), 4);
  let at = 0;
  return {
    /** Feed samples; after every `block` of them, run the analysis: (index, linear RMS, the 12 MFCCs). */
    feed(x: Float32Array, block: number, out: (index: number, rms: number, mfcc: Float32Array) => void) {
      for (let i = 0; i < x.length; i++) {
        ring[at] = x[i];
        at = (at + 1) % ring.length;
        if ((i + 1) % block === 0) {
          const k = z.execute(at);
          out(k, volume.getFloat32(0, true), new Float32Array(memory.buffer, z.mfccOut.value as number, 12));
        }
      }
    },
  };
}

const WL_BLOCK = 256; // 16 ms at 16 kHz, as HeadAudio's hop (its worklet's blockSize must be a multiple of 128)
const WL_NAMES = ['A', 'I', 'U', 'E', 'O', '-'];
const wlBase = { targetSampleRate: 16000, sampleCount: 1024, melFilterBankChannels: 30, compareMethod: 2, mfccNum: 12, useStandardization: false };

interface ClipResult {
  ours: { gapMm: number[]; ms: number };
  headaudio: { events: { viseme: number; t: number }[]; ms: number };
  wlipsync?: { names: string[]; volume: number[]; ms: number };
}

async function main() {
  const engine = await TalkingFaceEngine.load({ backend: 'cpu' });
  const n = engine.template.vertexCount;
  const { lips_inner_upper: upper, lips_inner_lower: lower } = engine.template.regions;
  const haModel = (await new Training().loadModel(headAudioModelUrl)).model;
  const sr = engine.manifest.audio.sample_rate;
  const wlModule = await WebAssembly.compileStreaming(fetch(wlipsyncWasmUrl));
  let wlProfile: Profile | null = null;

  /** uLipSync's calibration: MFCC snapshots of each vowel, taken by wlipsync's own analysis. `snapshots[name]`
   * holds 1024-sample excerpts; each class gets two profile entries (12 in all: its analysis computes only as many
   * coefficients as the profile has entries). */
  async function calibrate(snapshots: Record<string, number[][]>): Promise<number> {
    const probe = await wlipsync(wlModule, { ...wlBase, mfccDataCount: 1, mfccs: Array.from({ length: 12 }, (_, i) => ({ name: `c${i}`, mfccCalibrationDataList: [{ array: new Array(12).fill(i === 0 ? 1 : 0) }] })) }, sr);
    const per: Record<string, number[][]> = {};
    for (const name of WL_NAMES) {
      per[name] = [];
      for (const excerpt of snapshots[name] ?? []) {
        let last: number[] = [];
        probe.feed(Float32Array.from(excerpt), excerpt.length, (_, __, mfcc) => { last = Array.from(mfcc); });
        per[name].push(last);
      }
    }
    const count = Math.min(...WL_NAMES.map((n) => Math.floor(per[n].length / 2)));
    if (count < 1) throw new Error('wlipsync calibration: too few vowel snapshots');
    wlProfile = { ...wlBase, mfccDataCount: count, mfccs: [0, 1].flatMap((half) => WL_NAMES.map((name) => ({
      name, mfccCalibrationDataList: per[name].slice(half * count, (half + 1) * count).map((array) => ({ array })) }))) };
    return count;
  }

  async function compareClip(samples: number[]): Promise<ClipResult> {
    const x = Float32Array.from(samples);
    let t = performance.now();
    const a = await engine.animate(x, { unposed: true });
    const oursMs = performance.now() - t;
    const gapMm = Array.from(innerLipGaps(a.unposed!, a.frames, n, upper, lower), (g) => g / engine.unitsPerMm);

    const events: { viseme: number; t: number }[] = [];
    const proc = new Processor({ sampleRate: sr, processorOptions: {}, parameterData: {} },
      { port: { postMessage: (m: { event: string; viseme?: number; t?: number }) => { if (m.event === 'viseme') events.push({ viseme: m.viseme!, t: m.t! }); } } });
    proc._onmessage({ data: { event: 'model', model: haModel } });
    t = performance.now();
    for (let i = 0; i < x.length; i += 128) proc.process(x.subarray(i, Math.min(x.length, i + 128)));
    const haMs = performance.now() - t;
    let wl: ClipResult['wlipsync'];
    if (wlProfile) {
      const runner = await wlipsync(wlModule, wlProfile, sr);
      const names: string[] = [];
      const volume: number[] = [];
      t = performance.now();
      runner.feed(x, WL_BLOCK, (k, rms) => {
        names.push(wlProfile!.mfccs[k].name);
        // Its node's mouth scale: log10(rms) from minVolume -2.5 to maxVolume -1.5, clamped to 0..1 (dist/wlipsync.js).
        volume.push(Math.min(1, Math.max(0, (Math.log10(Math.max(rms, 1e-9)) + 2.5) / 1.0)));
      });
      wl = { names, volume, ms: performance.now() - t };
    }
    return { ours: { gapMm, ms: oursMs }, headaudio: { events, ms: haMs }, wlipsync: wl };
  }
  return { compareClip, calibrate, lookAheadMs: engine.manifest.look_ahead_ms, fps: engine.fps, sampleRate: sr, backend: engine.backend };
}

main().then(
  (api) => {
    Object.assign(globalThis, { compare: api });
    document.getElementById('status')!.textContent = 'ready';
  },
  (e: Error) => {
    Object.assign(globalThis, { compare: { error: `${e.name}: ${e.message}` } });
    document.getElementById('status')!.textContent = `failed: ${e.message}`;
  },
);

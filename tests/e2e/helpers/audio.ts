/** WAV files made in the test process from tests/fixtures/speech-kal.wav (16 kHz mono PCM16). */
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import type { Page } from '@playwright/test';

export const SPEECH = resolve(import.meta.dirname, '../../fixtures/speech-kal.wav');

/** The shipped model's numbers the tests need (models/manifest.json is their one source). */
const MANIFEST = JSON.parse(readFileSync(resolve(import.meta.dirname, '../../../models/manifest.json'), 'utf8')) as { audio: { sample_rate: number; fps: number } };
export const SAMPLE_RATE = MANIFEST.audio.sample_rate;
export const FPS = MANIFEST.audio.fps;

/** SPEECH's phones, force-aligned (tests/fixtures/speech-kal.phones.json): [ARPAbet phone, start s, end s]. */
export const SPEECH_PHONES: [string, number, number][] = JSON.parse(readFileSync(resolve(import.meta.dirname, '../../fixtures/speech-kal.phones.json'), 'utf8')).phones;

/** For each of SPEECH's phones in `set`, the frames (of `frames`) whose instant lies in it; empty ones left out. */
export function phoneSegments(set: Set<string>, frames: number): number[][] {
  return SPEECH_PHONES.filter(([p]) => set.has(p)).map(([, s, e]) => {
    const out: number[] = [];
    for (let f = Math.ceil(s * FPS); f < e * FPS && f < frames; f++) out.push(f);
    return out;
  }).filter((seg) => seg.length > 0);
}

export function speechSamples(): { samples: Float32Array; rate: number } {
  return { samples: readWav16(SPEECH), rate: SAMPLE_RATE };
}

/** Frames the engine makes for a WAV file at `path` (round(duration * fps), as the engine counts them). */
export function framesOf(path: string): number {
  return Math.round((readWav16(path).length / SAMPLE_RATE) * FPS);
}

/** A mono 16-bit PCM WAV file's samples at the model's rate (the corpus's and the sample clips' format), chunks walked to "data". */
export function readWav16(path: string): Float32Array {
  const b = readFileSync(path);
  if (b.readUInt32LE(24) !== SAMPLE_RATE || b.readUInt16LE(34) !== 16 || b.readUInt16LE(22) !== 1) throw new Error(`${path}: expected mono 16-bit PCM at the model's ${SAMPLE_RATE} Hz`);
  let o = 12;
  while (b.toString('ascii', o, o + 4) !== 'data') o += 8 + b.readUInt32LE(o + 4);
  const n = b.readUInt32LE(o + 4) / 2;
  return Float32Array.from({ length: n }, (_, i) => b.readInt16LE(o + 8 + 2 * i) / 32768);
}

/** 16-bit PCM WAV; `channels` are interleaved from the given per-channel arrays. */
export function wav(channels: Float32Array[], rate: number): Buffer {
  const n = channels[0].length;
  const c = channels.length;
  const b = Buffer.alloc(44 + 2 * n * c);
  b.write('RIFF', 0); b.writeUInt32LE(36 + 2 * n * c, 4); b.write('WAVE', 8); b.write('fmt ', 12);
  b.writeUInt32LE(16, 16); b.writeUInt16LE(1, 20); b.writeUInt16LE(c, 22); b.writeUInt32LE(rate, 24);
  b.writeUInt32LE(2 * rate * c, 28); b.writeUInt16LE(2 * c, 32); b.writeUInt16LE(16, 34); b.write('data', 36); b.writeUInt32LE(2 * n * c, 40);
  for (let i = 0; i < n; i++) for (let k = 0; k < c; k++) b.writeInt16LE(Math.max(-32768, Math.min(32767, Math.round(channels[k][i] * 32767))), 44 + 2 * (i * c + k));
  return b;
}

/** Linear-interpolation resampling (good enough for speech at these rates in a test). */
export function resample(x: Float32Array, from: number, to: number): Float32Array {
  const n = Math.floor((x.length * to) / from);
  const y = new Float32Array(n);
  for (let i = 0; i < n; i++) {
    const p = (i * from) / to;
    const k = Math.floor(p);
    const t = p - k;
    y[i] = (1 - t) * x[k] + t * (x[Math.min(k + 1, x.length - 1)] ?? 0);
  }
  return y;
}

/** Per frame of the demo's current take: mean height of the upper inner lip above the lower one, in mm. */
export async function lipGaps(page: Page): Promise<number[]> {
  return page.evaluate(() => {
    const tf = (globalThis as unknown as { talkingFace: { template: { vertexCount: number; regions: Record<string, Uint32Array> }; engine: { unitsPerMm: number }; take: { animation: { frames: number; unposed: Float32Array } } } }).talkingFace;
    const { regions, vertexCount: n } = tf.template;
    const up = Array.from(regions.lips_inner_upper).filter((v) => !regions.lips_inner_lower.includes(v));
    const lo = Array.from(regions.lips_inner_lower).filter((v) => !regions.lips_inner_upper.includes(v));
    const u = tf.take.animation.unposed;
    const mmPerUnit = 1 / tf.engine.unitsPerMm;
    const gaps: number[] = [];
    for (let f = 0; f < tf.take.animation.frames; f++) {
      const y = (idx: number[]) => idx.reduce((s, v) => s + u[(f * n + v) * 3 + 1], 0) / idx.length;
      gaps.push(mmPerUnit * (y(up) - y(lo)));
    }
    return gaps;
  });
}

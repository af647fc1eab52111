/**
 * The demo's sample clips (models/samples/, written by training/src/talkingface/samples.py): the index, the
 * audio and the ground truth of test-split clips, checked against the index's hashes.
 */
import { sha256Hex } from '../model/artefacts';
import { fetchBody } from '../model/fetch-body';

const SAMPLES_URL = '/models/samples/';

export interface SampleEntry {
  name: string; text: string; voice: string; source: string; frames: number; seconds: number;
  audio: string; ground_truth: string; vertices: number; audio_sha256: string; ground_truth_sha256: string;
  lip_gap_mm: number[]; phones: [string, number, number][];
}

export interface SampleIndex {
  units: string;
  clips: SampleEntry[];
}

/** Ground truth of a sample clip: the subject's neutral face, the unposed frames and poses (template units). */
export interface Truth {
  template: Float32Array;
  unposed: Float32Array;
  pose: Float32Array;
  frames: number;
  /** The sample's inner-lip gap per frame (mm) and aligned phones, from its index (for the timeline). */
  lipGapMm?: number[];
  phones?: [string, number, number][];
}

/** A sample file's bytes (a stalled download fails, naming it; `signal` cancels). */
async function sampleFile(name: string, signal?: AbortSignal): Promise<ArrayBuffer> {
  const r = await fetchBody(`${SAMPLES_URL}${name}`, { signal }).catch((e: Error) => {
    throw signal?.aborted ? e : new Error(`${name}: ${e.message}`);
  });
  if (!r.ok) throw new Error(`${name === 'index.json' ? '' : `${name}: `}HTTP ${r.status}`);
  return r.bytes;
}

export async function fetchSampleIndex(): Promise<SampleIndex> {
  return JSON.parse(new TextDecoder().decode(await sampleFile('index.json'))) as SampleIndex;
}

/** Fill the demo's sample menu from the index; without one the menu is disabled, its title saying why. */
export async function fillSampleSelect(select: HTMLSelectElement): Promise<SampleIndex | null> {
  try {
    const index = await fetchSampleIndex();
    for (const c of index.clips) {
      const o = document.createElement('option');
      o.value = c.name;
      o.textContent = `"${c.text}" (${c.source === 'human' ? 'recorded voice' : c.voice}, ${c.seconds.toFixed(1)} s)`;
      select.append(o);
    }
    return index;
  } catch (e) {
    select.disabled = true;
    select.title = `No sample clips: ${(e as Error).message}`;
    return null;
  }
}

/** The menu names the take when it is a sample, else shows its placeholder (so choosing a sample again is a change). */
export function markSample(select: HTMLSelectElement, index: SampleIndex | null, name: string | undefined): void {
  select.value = name && index?.clips.some((c) => c.name === name) ? name : '';
}

/** A sample's audio bytes and decoded ground truth, both checked against the index. */
export async function fetchSample(c: SampleEntry, vertices: number, unitsPerMm: number, signal?: AbortSignal): Promise<{ audio: ArrayBuffer; truth: Truth }> {
  const [audio, truthBytes] = await Promise.all([c.audio, c.ground_truth].map((f) => sampleFile(f, signal)));
  if ((await sha256Hex(audio)) !== c.audio_sha256 || (await sha256Hex(truthBytes)) !== c.ground_truth_sha256) {
    throw new Error('the sample files do not match their index (corrupt download?)');
  }
  if (c.vertices !== vertices) throw new Error(`the sample has ${c.vertices} vertices, the face ${vertices}`);
  return { audio, truth: { ...decodeTruth(truthBytes, vertices, c.frames, unitsPerMm), lipGapMm: c.lip_gap_mm, phones: c.phones } };
}

/** samples.py's layout: float32 (N,3) neutral face; int16 (F,N,3) micrometre offsets; float32 (F,6) pose (units). */
export function decodeTruth(bytes: ArrayBuffer, n: number, frames: number, unitsPerMm: number): Truth {
  const expected = n * 12 + frames * n * 6 + frames * 24;
  if (bytes.byteLength !== expected) throw new Error(`ground truth has ${bytes.byteLength} bytes, expected ${expected}`);
  const view = new DataView(bytes);
  const template = new Float32Array(n * 3);
  for (let i = 0; i < n * 3; i++) template[i] = view.getFloat32(4 * i, true);
  const unposed = new Float32Array(frames * n * 3);
  const base = n * 12;
  for (let i = 0; i < frames * n * 3; i++) unposed[i] = template[i % (n * 3)] + (view.getInt16(base + 2 * i, true) / 1000) * unitsPerMm;
  const pose = new Float32Array(frames * 6);
  const pb = base + frames * n * 6;
  for (let i = 0; i < frames * 6; i++) pose[i] = view.getFloat32(pb + 4 * i, true);
  return { template, unposed, pose, frames };
}

/** Frame f of a prediction moved onto the truth's subject: their neutral face plus the predicted displacement. */
export function onTruthFace(truth: Truth, templatePositions: Float32Array): (f: number, unposed: Float32Array) => Float32Array {
  const scratch = new Float32Array(templatePositions.length); // reused: callers use each frame at once
  return (_f, u) => {
    for (let i = 0; i < scratch.length; i++) scratch[i] = truth.template[i] + u[i] - templatePositions[i];
    return scratch;
  };
}

/** Per-vertex distance (mm) between a predicted frame and the truth's frame f. */
export function vertexErrors(pred: Float32Array, truth: Truth, f: number, mmPerUnit: number): Float32Array {
  const n = pred.length / 3;
  const err = new Float32Array(n);
  for (let v = 0; v < n; v++) {
    const o = (f * n + v) * 3;
    err[v] = mmPerUnit * Math.hypot(pred[3 * v] - truth.unposed[o], pred[3 * v + 1] - truth.unposed[o + 1], pred[3 * v + 2] - truth.unposed[o + 2]);
  }
  return err;
}

/** The paper's E_vl for a take: mean over frames of the largest lip-vertex error (mm). `predicted(f)`: frame f as drawn. */
export function clipLipError(predicted: (f: number) => Float32Array, frames: number, truth: Truth, lipMask: Uint8Array, mmPerUnit: number): number {
  const count = Math.min(truth.frames, frames);
  let sum = 0;
  for (let f = 0; f < count; f++) {
    const err = vertexErrors(predicted(f), truth, f, mmPerUnit);
    let worst = 0;
    for (let v = 0; v < err.length; v++) if (lipMask[v]) worst = Math.max(worst, err[v]);
    sum += worst;
  }
  return sum / count;
}

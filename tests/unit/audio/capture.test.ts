/**
 * AudioCapture.start (src/audio/capture.ts) on stand-in Web Audio: where the stream cannot be connected at the
 * model's rate (Firefox, a stream at another rate) it runs at the device's, and every context it could not use,
 * or made before the capture failed to start, is closed (none is left running, one per Record pressed).
 */
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { AudioCapture } from '../../../src/audio/capture';

class Context {
  static made: Context[] = [];
  static refuseModelRate = false; // createMediaStreamSource throws on a context made at a given rate
  static refuseWorklet = false; // the worklet module cannot be loaded
  readonly sampleRate: number;
  state = 'running';
  closed = false;
  audioWorklet = { addModule: async () => { if (Context.refuseWorklet) throw new Error('refused by the page\'s policy'); } };
  destination = {};
  constructor(private readonly options: { sampleRate?: number } = {}) {
    this.sampleRate = options.sampleRate ?? 48000;
    Context.made.push(this);
  }
  createMediaStreamSource() {
    if (Context.refuseModelRate && this.options.sampleRate) throw new Error('NotSupportedError: different sample rates');
    return { connect() {}, disconnect() {} };
  }
  addEventListener() {}
  removeEventListener() {}
  async close() {
    this.closed = true;
    this.state = 'closed';
  }
}
class WorkletNode {
  port = { onmessage: null as unknown, postMessage() {} };
  connect() {}
  disconnect() {}
}
const stream = {
  getAudioTracks: () => [{ readyState: 'live', addEventListener() {}, removeEventListener() {} }],
  addEventListener() {},
  removeEventListener() {},
} as unknown as MediaStream;

beforeEach(() => {
  Context.made = [];
  [Context.refuseModelRate, Context.refuseWorklet] = [false, false];
  vi.stubGlobal('AudioContext', Context);
  vi.stubGlobal('AudioWorkletNode', WorkletNode);
});
afterEach(() => vi.unstubAllGlobals());

describe('AudioCapture.start', () => {
  it("runs at the model's rate where the browser connects the stream there, with one context", async () => {
    const capture = await AudioCapture.start(stream, 16000, () => undefined);
    expect([capture.contextRate, Context.made.length]).toEqual([16000, 1]);
    capture.stop();
  });

  it("falls back to the device's rate, closing the context it could not use", async () => {
    Context.refuseModelRate = true;
    const capture = await AudioCapture.start(stream, 16000, () => undefined);
    expect(capture.contextRate).toBe(48000);
    expect(Context.made.map((c) => c.closed)).toEqual([true, false]);
    capture.stop();
  });

  it('closes its context where the capture cannot start (the worklet refused), and says why', async () => {
    Context.refuseWorklet = true;
    await expect(AudioCapture.start(stream, 16000, () => undefined)).rejects.toThrow(/the audio capture could not be loaded/);
    expect(Context.made.map((c) => c.closed)).toEqual([true]);
  });
});

/**
 * A stand-in Web Audio clock for unit tests of what plays sound on it (player/stream-playback.ts, speakStream): an
 * AudioContext whose time the test moves and which records the sources started, an AudioBuffer, and animation frames
 * drawn when the test says. `installAudioClock()` in a beforeEach; `drawAt(t)` moves the clock and draws one frame.
 */
export interface FakeSource {
  at: number;
  length: number;
  stopped: boolean;
  onended: (() => void) | null;
}

export class FakeContext {
  /** The one made last (undefined until one is made in this test: `installAudioClock` forgets the last test's). */
  static last: FakeContext;
  currentTime = 0;
  state = 'running';
  destination = {};
  sources: FakeSource[] = [];
  constructor() {
    FakeContext.last = this;
  }
  resume() { return Promise.resolve(); }
  close() { return Promise.resolve(); }
  createGain() { return { gain: { value: 1 }, connect() {} }; }
  createBufferSource() {
    const s = { at: NaN, length: 0, stopped: false, onended: null as (() => void) | null, buffer: null as { length: number } | null,
      connect() {}, start(at: number) { s.at = at; s.length = s.buffer!.length; }, stop() { s.stopped = true; } };
    this.sources.push(s);
    return s;
  }
}

export class FakeBuffer {
  readonly length: number;
  readonly duration: number;
  private data: Float32Array;
  constructor({ length, sampleRate }: { length: number; sampleRate: number }) {
    [this.length, this.duration, this.data] = [length, length / sampleRate, new Float32Array(length)];
  }
  getChannelData() { return this.data; }
}

let callbacks: (() => void)[] = [];

/** The stand-ins in place of the browser's (call in a beforeEach); the animation frames asked for are forgotten. */
export function installAudioClock(): void {
  callbacks = [];
  FakeContext.last = undefined as unknown as FakeContext;
  Object.assign(globalThis, { AudioContext: FakeContext, AudioBuffer: FakeBuffer,
    requestAnimationFrame: (cb: () => void) => callbacks.push(cb), cancelAnimationFrame: () => undefined });
}

/** Move the last context's clock to `time` and draw one animation frame. */
export function drawAt(time: number): void {
  FakeContext.last.currentTime = time;
  const cbs = callbacks;
  callbacks = [];
  for (const cb of cbs) cb();
}

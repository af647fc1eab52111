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

export class FakeContext extends EventTarget {
  /** The one made last (undefined until one is made in this test: `installAudioClock` forgets the last test's). */
  static last: FakeContext;
  /** Set: contexts made from now on start suspended, and resume() waits until allow() (the autoplay rules). */
  static heldBack = false;
  currentTime = 0;
  state: AudioContextState = 'running';
  destination = {};
  sources: FakeSource[] = [];
  resumes = 0; // resume() calls
  private allowed: () => void = () => undefined;
  constructor() {
    super();
    FakeContext.last = this;
    if (FakeContext.heldBack) this.state = 'suspended';
  }
  resume() {
    this.resumes++;
    if (this.state !== 'suspended') return this.state === 'closed' ? Promise.reject(new Error('closed')) : Promise.resolve();
    if (FakeContext.heldBack) return new Promise<void>((resolve) => (this.allowed = resolve));
    this.setState('running');
    return Promise.resolve();
  }
  /** A gesture lets a held-back context run: a resume() waiting, or the next, resolves. */
  allow() {
    FakeContext.heldBack = false;
    this.setState('running');
    this.allowed();
  }
  close() {
    this.setState('closed');
    return Promise.resolve();
  }
  private setState(state: AudioContextState) {
    if (this.state === state) return;
    this.state = state;
    this.dispatchEvent(new Event('statechange'));
  }
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
  FakeContext.heldBack = false;
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

/**
 * Live audio in: a MediaStream (the microphone, or any stream) -> mono Float32Array pieces at the
 * model's sample rate, as they arrive, through an AudioWorklet. Library code: Web Audio, no DOM.
 *
 * The AudioContext runs at the model's rate when the browser allows it (Chromium resamples the
 * stream for us); otherwise at the device's rate, and a streaming resampler brings the pieces down.
 * The worklet module (capture-worklet.js) is loaded from a blob: URL of its text, so the page makes no request for
 * it; where a Content-Security-Policy refuses blob: scripts, from the library's own copy of the file.
 */
import WORKLET from './capture-worklet.js?raw';
import { StreamResampler } from './resample';

export class MicrophoneError extends Error {
  override name = 'MicrophoneError';
  /** `notConnected`: the microphone asked for by its id (openMicrophone(deviceId)) is not there. */
  constructor(message: string, readonly notConnected = false) {
    super(message);
  }
}

/**
 * Whether this document's permissions policy lets it use the microphone (Chromium's document.featurePolicy; true where
 * the browser does not say): a frame without allow="microphone", or a sandboxed frame without an origin, would be
 * refused by the browser before any person is asked, with "access was denied".
 */
function frameAllowsMicrophone(): boolean {
  const policy = (globalThis.document as (Document & { featurePolicy?: { allowsFeature(f: string): boolean } }) | undefined)?.featurePolicy;
  return policy?.allowsFeature('microphone') ?? true;
}

/** The browser's entries that follow the system's choice rather than name a device. */
export const SYSTEM_ENTRY = /^(default|communications)$/;

/** An audio input the page may open (listMicrophones()). */
export interface Microphone {
  /** What openMicrophone() takes to open this one (stable for this site until the person clears its data). */
  deviceId: string;
  /** Its name, or "Microphone N" where the browser gives none. */
  label: string;
}

/**
 * The audio inputs, as the browser lists them (its "default" and "communications" entries, which follow the
 * system's choice, included). Empty where the page cannot list devices, and where the browser hides them until the
 * page has been allowed a microphone (it then lists at most one, without an id).
 */
export async function listMicrophones(): Promise<Microphone[]> {
  const devices = await globalThis.navigator?.mediaDevices?.enumerateDevices?.().catch(() => []) ?? []; // (a page that may not list them: none)
  const inputs: Microphone[] = [];
  let place = 0; // among the devices (not the system's default and communications entries)
  for (const d of devices) {
    if (d.kind !== 'audioinput' || !d.deviceId) continue;
    const system = SYSTEM_ENTRY.test(d.deviceId);
    if (!system) place++;
    inputs.push({ deviceId: d.deviceId, label: d.label || (system ? d.deviceId : `Microphone ${place}`) });
  }
  return inputs;
}

/**
 * getUserMedia with messages a person can act on: the system's default microphone, or the one `deviceId` names
 * (listMicrophones()), and no other: where it is not connected, a MicrophoneError says so.
 */
export async function openMicrophone(deviceId?: string): Promise<MediaStream> {
  if (deviceId !== undefined && (typeof deviceId !== 'string' || !deviceId)) {
    throw new MicrophoneError('deviceId must be a microphone\'s id, a non-empty string (listMicrophones() gives them)');
  }
  if (!globalThis.navigator?.mediaDevices?.getUserMedia) {
    throw new MicrophoneError('this page cannot use a microphone here (it needs a secure context: https or localhost)');
  }
  if (!frameAllowsMicrophone()) {
    throw new MicrophoneError('this page is in a frame that is not allowed the microphone: the page that embeds it must give its <iframe> allow="microphone" ' +
      '(and a sandboxed frame allow-same-origin as well); or open an audio file instead');
  }
  const chosen = deviceId ? { deviceId: { exact: deviceId } } : {};
  try {
    return await navigator.mediaDevices.getUserMedia({ audio: { ...chosen, channelCount: 1, echoCancellation: false, noiseSuppression: false, autoGainControl: false } });
  } catch (e) {
    const name = (e as DOMException).name;
    if (name === 'NotAllowedError' || name === 'SecurityError') throw new MicrophoneError('microphone access was denied; allow it in the browser (the address bar\'s site settings) and try again, or open an audio file instead');
    if (deviceId && (name === 'NotFoundError' || name === 'OverconstrainedError')) throw new MicrophoneError('the chosen microphone is not connected; plug it back in, or choose another', true);
    if (name === 'NotFoundError' || name === 'OverconstrainedError') throw new MicrophoneError('no microphone was found; plug one in, or open an audio file instead');
    if (name === 'NotReadableError' || name === 'AbortError') throw new MicrophoneError('the microphone is in use by another application or could not be started');
    throw new MicrophoneError(`the microphone could not be opened: ${(e as Error).message || name}`);
  }
}

export interface CaptureOptions {
  /** Samples per piece delivered to onSamples, at the model's rate (default 256: 16 ms at 16 kHz). */
  block?: number;
  /** Play the stream to the speakers as well (default false: no feedback loop with a microphone). */
  monitor?: boolean;
  /**
   * Called when sound stops arriving (once, until a track comes back): every audio track of the stream has ended or
   * left it (a microphone unplugged, its track stopped, a page's clip over), or the browser suspended the audio and
   * would not resume it. The capture goes on, silent, and follows an audio track added to the stream later; stop it
   * to release the microphone.
   */
  onInterrupted?: (error: MicrophoneError) => void;
}

/** How long a suspended context is given to resume before the capture says it was interrupted. */
const RESUME_WAIT_MS = 1000;
/** How often the stream's tracks are looked at (a track a script stops fires no event). */
const TRACK_POLL_MS = 500;

/** A running capture: stop() releases the worklet, the context and (if asked) the stream's tracks. */
export class AudioCapture {
  private stopped = false;
  private unwatch: () => void = () => undefined;

  private constructor(
    readonly context: AudioContext,
    private readonly node: AudioWorkletNode,
    private source: MediaStreamAudioSourceNode,
    readonly stream: MediaStream,
    /** The rate of the pieces handed to onSamples (the model's). */
    readonly sampleRate: number,
    /** The rate the context actually runs at. */
    readonly contextRate: number,
    private readonly flushed: { stopped: (() => void) | null },
  ) {}

  static async start(stream: MediaStream, sampleRate: number, onSamples: (samples: Float32Array) => void, options: CaptureOptions = {}): Promise<AudioCapture> {
    if (stream.getAudioTracks().length === 0) throw new MicrophoneError('the stream has no audio track');
    if (!stream.getAudioTracks().some((t) => t.readyState === 'live')) throw new MicrophoneError('the stream\'s audio has ended (its tracks were stopped)');
    if (options.block !== undefined && !(Number.isInteger(options.block) && options.block > 0)) throw new RangeError(`block must be a whole number of samples, not ${options.block}`);
    let context: AudioContext | undefined;
    let source: MediaStreamAudioSourceNode;
    try {
      context = new AudioContext({ sampleRate, latencyHint: 'interactive' });
      source = context.createMediaStreamSource(stream);
    } catch (atModelRate) {
      // Some browsers cannot connect a stream to a context at another rate (Firefox): run at the device's rate (and
      // resample); if that fails too, both reasons are reported. The context that could not be used is closed.
      discard(context);
      try {
        context = new AudioContext({ latencyHint: 'interactive' });
        source = context.createMediaStreamSource(stream);
      } catch (e) {
        discard(context);
        throw new Error(`the microphone could not be connected to the audio system (at ${sampleRate} Hz: ${(atModelRate as Error).message}; ` +
          `at the device's rate: ${(e as Error).message})`);
      }
    }
    const rate = context.sampleRate;
    const block = Math.max(128, Math.round(((options.block ?? 256) * rate) / sampleRate));
    let node: AudioWorkletNode;
    try {
      await addCaptureModule(context);
      node = new AudioWorkletNode(context, 'talking-face-capture', { numberOfInputs: 1, numberOfOutputs: 0, processorOptions: { block } });
    } catch (e) {
      discard(context); // a capture that could not start holds no audio context
      throw e;
    }
    const resampler = rate === sampleRate ? null : new StreamResampler(rate, sampleRate);
    const capture = { stopped: null as (() => void) | null };
    node.port.onmessage = (e: MessageEvent<Float32Array | string>) => {
      if (e.data === 'stopped') {
        capture.stopped?.();
        return;
      }
      if (typeof e.data === 'string') return;
      const piece = resampler ? resampler.push(e.data) : e.data;
      if (piece.length > 0) onSamples(piece);
    };
    source.connect(node);
    if (options.monitor) source.connect(context.destination);
    if (context.state === 'suspended') {
      try {
        await context.resume();
      } catch (e) {
        // A context that cannot run delivers no samples: say so rather than record silence.
        source.disconnect();
        node.disconnect();
        await context.close();
        throw new Error(`the audio system would not start (${(e as Error).message}); click the page and try again`);
      }
    }
    const made = new AudioCapture(context, node, source, stream, sampleRate, rate, capture);
    made.watch(options.onInterrupted, Boolean(options.monitor));
    return made;
  }

  /** Follow the stream's tracks and the context's state (CaptureOptions.onInterrupted). */
  private watch(onInterrupted: CaptureOptions['onInterrupted'], monitor: boolean): void {
    const { stream, context } = this;
    const live = () => stream.getAudioTracks().some((t) => t.readyState === 'live');
    let said = false; // once per interruption: a track added starts another
    const say = (why: string) => {
      if (this.stopped || said) return;
      said = true;
      onInterrupted?.(new MicrophoneError(why));
    };
    const gone = () => live() || say('the microphone stopped sending sound (unplugged, or its track was stopped)');
    const added = (ev: MediaStreamTrackEvent) => {
      if (ev.track.kind !== 'audio' || ev.track.readyState !== 'live' || this.stopped) return;
      // A source node stays on the track it was made with: a track added later (a page's clip played again) gets its own.
      said = false;
      this.source.disconnect();
      this.source = context.createMediaStreamSource(new MediaStream([ev.track]));
      this.source.connect(this.node);
      if (monitor) this.source.connect(context.destination);
      ev.track.addEventListener('ended', gone);
    };
    const suspended = () => {
      if (context.state === 'running' && live()) said = false; // sound again: a later loss is reported too
      if (this.stopped || context.state === 'running' || context.state === 'closed') return;
      void context.resume().catch(() => undefined); // deliberate: whether it ran is read below
      setTimeout(() => context.state !== 'running' && say('the browser suspended the audio (another application took it, or the page was put aside)'), RESUME_WAIT_MS);
    };
    for (const t of stream.getAudioTracks()) t.addEventListener('ended', gone);
    // A track stopped by a script ends without an 'ended' event: its state is read too.
    const poll = setInterval(gone, TRACK_POLL_MS);
    stream.addEventListener('removetrack', gone);
    stream.addEventListener('addtrack', added);
    context.addEventListener('statechange', suspended);
    this.unwatch = () => {
      clearInterval(poll);
      for (const t of stream.getAudioTracks()) t.removeEventListener('ended', gone);
      stream.removeEventListener('removetrack', gone);
      stream.removeEventListener('addtrack', added);
      context.removeEventListener('statechange', suspended);
    };
  }

  /** Stop capturing. `releaseStream` also stops the stream's tracks (the browser's recording indicator goes off). */
  async stop(releaseStream = true): Promise<void> {
    if (this.stopped) return;
    this.stopped = true;
    this.unwatch();
    if (this.context.state === 'running') {
      // Wait for the worklet's last samples (bounded: a closed or stalled context must not hang stop()).
      await new Promise<void>((resolve) => {
        const timer = setTimeout(resolve, 2000);
        this.flushed.stopped = () => {
          clearTimeout(timer);
          resolve();
        };
        this.node.port.postMessage('stop');
      });
    }
    this.node.port.onmessage = null;
    this.source.disconnect();
    this.node.disconnect();
    if (releaseStream) stopTracks(this.stream);
    // Deliberate: closing can only fail on a context that is already closed, which is the goal.
    await this.context.close().catch(() => undefined); // fails only on a context already closed: the goal
  }
}

/** The worklet's file, beside this module's code in both builds (scripts/worklet-file.ts); not a literal, so Vite leaves it. */
const WORKLET_FILE = 'capture-worklet.js';

/** The worklet's module: a blob: URL of its text, else (a Content-Security-Policy without blob: in script-src) its file. */
/** Close a context the capture will not use (closing fails only where it is already closed: the goal). */
function discard(context: AudioContext | undefined): void {
  void context?.close().catch(() => undefined); // (fails only when already closed: the goal)
}

async function addCaptureModule(context: AudioContext): Promise<void> {
  const url = URL.createObjectURL(new Blob([WORKLET], { type: 'text/javascript' }));
  try {
    await context.audioWorklet.addModule(url);
  } catch (fromBlob) {
    const file = new URL(WORKLET_FILE, import.meta.url).href;
    await context.audioWorklet.addModule(file).catch((e: Error) => {
      throw new Error(`the audio capture could not be loaded (${(fromBlob as Error).message}; from the library's files: ${e.message}): ` +
        `a Content-Security-Policy must allow blob: or the page's own scripts (script-src 'self'), and ${file} must be served ` +
        '(a bundler does not copy it: copy capture-worklet.js there, from the package\'s dist/lib/npm/ or the build\'s lib/)');
    });
  } finally {
    URL.revokeObjectURL(url);
  }
}

/** Let a stream's devices go: every track stopped (the browser's recording indicator goes off for a microphone). */
export function stopTracks(stream: MediaStream | null | undefined): void {
  for (const t of stream?.getTracks() ?? []) t.stop();
}

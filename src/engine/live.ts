/**
 * Live animation: a MediaStream (the microphone) -> AudioWorklet capture -> StreamSession -> frames,
 * as the person speaks. The take is kept (mono, model rate) so it can be replayed or animated again.
 */
import { AudioCapture, type CaptureOptions } from '../audio/capture';
import type { StreamSession } from './stream';

export interface LiveOptions extends CaptureOptions {
  /** Keep the captured audio for replay (default true). A ten-minute take is 38 MB at 16 kHz. */
  keepAudio?: boolean;
  /**
   * Stay live on a device slower than real time: when more than this many frames wait to be computed,
   * skip to the newest (default 15, half a second at 30 fps; Infinity keeps every frame, as offline).
   */
  maxLagFrames?: number;
  /** Called when processing a piece fails (the session stops). */
  onError?: (error: Error) => void;
  /** Frames also carry ARKit weights, visemes and head rotations (Frames.blendshapes). */
  blendshapes?: boolean;
  /** How far the head's own motion turns the head in this session (default: engine.headMotionScale). */
  headMotionScale?: number;
}

export class LiveSession {
  private pieces: Float32Array[] = [];
  private samples = 0;
  private stopping: Promise<Float32Array> | null = null;
  private closed = false; // the capture has delivered its last piece
  private failed: Error | null = null;
  private onError: LiveOptions['onError'];

  private constructor(
    readonly stream: StreamSession,
    private capture: AudioCapture | null,
    private readonly keepAudio: boolean,
  ) {}

  /** Capture `media` into `stream` (made with maxLagFrames = LiveSession.maxLag(options): see LiveOptions). */
  static async start(stream: StreamSession, media: MediaStream, options: LiveOptions = {}): Promise<LiveSession> {
    const session = new LiveSession(stream, null, options.keepAudio ?? true);
    session.onError = options.onError;
    session.capture = await AudioCapture.start(media, stream.sampleRate, (piece) => session.receive(piece, options.onError), options);
    return session;
  }

  /** The stream's lag limit for live use (LiveOptions.maxLagFrames, default 15 frames). */
  static maxLag(options: LiveOptions = {}): number {
    return options.maxLagFrames ?? 15;
  }

  /** Seconds of audio captured so far. */
  get seconds(): number {
    return this.samples / this.stream.sampleRate;
  }

  /** The AudioContext's own input latency (s), which comes before the samples reach the engine. */
  get inputLatencySeconds(): number {
    return this.capture?.context.baseLatency ?? 0;
  }

  private receive(piece: Float32Array, onError?: (error: Error) => void): void {
    if (this.closed || this.failed) return;
    this.samples += piece.length;
    if (this.keepAudio) this.pieces.push(piece);
    const failed = (e: Error): void => {
      if (this.failed) return;
      this.failed = e;
      void this.capture?.stop();
      onError?.(e);
    };
    try {
      this.stream.push(piece).catch(failed);
    } catch (e) {
      failed(e as Error); // (a stream cancelled meanwhile refuses at once)
    }
  }

  /**
   * Stop capturing, emit the remaining frames, and return the take (empty when keepAudio is false). The last frames
   * failing (onError tells it) does not lose the take: its sound is returned all the same.
   */
  stop(): Promise<Float32Array> {
    this.stopping ??= (async () => {
      await this.capture?.stop(); // the worklet's last pieces arrive before this resolves
      this.closed = true;
      try {
        if (!this.failed) await this.stream.end();
      } catch (e) {
        this.failed = e as Error; // the last frames could not be made: told, and the take's sound is still returned
        this.onError?.(this.failed);
      }
      const take = new Float32Array(this.keepAudio ? this.samples : 0);
      let o = 0;
      for (const p of this.pieces) {
        take.set(p, o);
        o += p.length;
      }
      this.pieces = [];
      return take;
    })();
    return this.stopping;
  }
}

/**
 * The one player the demo and <talking-face> share: it shows a frame of a take on a FaceView (unposed face plus
 * head pose), plays the take's audio with the face in sync on the AudioContext's clock, shows streamed frames
 * live, and says what is worth knowing about the audio (silence, clipping, length).
 */
import type { Animation, Frames } from '../engine/frames';
import type { BlendshapeFrames } from '../avatar/weights';
import { LIVE_REST_FRAMES, SPEECH_PROBABILITY } from '../encoders/voice-activity';
import { resumeOnGesture } from './autoplay';
import { heardTime } from './stream-timeline';
import { stopTracks } from '../audio/capture';

/** What a Player draws on: the template's face (render/face-view.ts) or a glTF avatar (avatar/avatar-view.ts). */
export interface PlayerView {
  /** A frame's unposed face I + O (template units). */
  setVertices(vertices: Float32Array): void;
  /** The head pose: axis-angle (radians) and translation (template units). */
  setPose(rx: number, ry: number, rz: number, tx: number, ty: number, tz: number): void;
  /** Frame `frame` of the take's (or stream's) ARKit weights, visemes and head rotation, when it carries them. */
  setBlendshapes?(blendshapes: BlendshapeFrames, frame: number): void;
  /** How raised the tongue is, 0..1 (a view that draws one). */
  setTongue?(raise: number): void;
  /** Speech is shown (true) or the face returns to rest (false), for a view with idle life. */
  setSpeaking?(on: boolean): void;
  /** The model's face at rest, for a view with idle life. */
  setRestFace?(rest: Float32Array): void;
}

export interface PlayerOptions {
  /** Called whenever a frame of the take is shown (by play, seek or show). */
  onFrame?: (frame: number) => void;
  /** Called when playback reaches the end (not on stop(), not when looping). */
  onEnded?: () => void;
  /**
   * Called when the browser holds the sound back until a person's gesture on the page (autoplay rules: a page that
   * plays before any click or key press); playback starts at the next one, and onUnblocked is called.
   */
  onBlocked?: () => void;
  onUnblocked?: () => void;
}

/**
 * Live frames come in batches when the device is slow (a batch per engine run): they are shown one after another,
 * each this fraction of a frame's time after the last (a little faster than real time, so a backlog drains) ...
 */
const LIVE_SPACING = 0.8;
/** ... and at most this far behind their batch (ms): older ones are dropped rather than shown late. */
const LIVE_BACKLOG_MS = 250;

interface Playing {
  source: AudioBufferSourceNode;
  startedAt: number;
  fromFrame: number;
  finish: () => void;
}

/** What a disposed Player's play() and tap() say. */
const DISPOSED = 'the face it played on is gone (its element removed, or its avatar changed)';

export class Player {
  /** Start again from the first frame when the end is reached. */
  loop = false;
  private animation: Animation | null = null;
  private buffer: AudioBuffer | null = null;
  private shape: ((frame: number, unposed: Float32Array) => Float32Array) | null = null;
  private context: AudioContext | null = null;
  private disposed = false;
  private tapNode: MediaStreamAudioDestinationNode | null = null; // where the sound also goes while tapped
  private gain: GainNode | null = null; // the volume, between the sound and the speakers (not the tap)
  private level = 1;
  private playing: Playing | null = null;
  private currentFrame = 0;
  private liveQuiet = LIVE_REST_FRAMES; // frames since the live input last held speech
  private liveQueue: { frames: Frames; f: number; due: number }[] = []; // live frames to show, each at its time
  private liveTick = 0; // the animation frame that shows them (0: none asked)
  private forgetGesture: () => void = () => undefined; // removes the listeners watchAutoplay left on the document
  private streaming: (() => void) | null = null; // stops the streamed speech playing (player/stream-playback.ts)

  /** `unitsPerMm`: the template's units per mm (the engine's; poses carry mm translations). */
  constructor(private readonly view: PlayerView, public unitsPerMm: number, private readonly options: PlayerOptions = {}) {}

  /**
   * A new take to show and play. `shape` maps frame f's unposed face to what is drawn (e.g. onto another
   * subject's face); by default it is drawn as is. The animation must carry `unposed` frames.
   */
  load(animation: Animation, buffer: AudioBuffer, shape?: (frame: number, unposed: Float32Array) => Float32Array): void {
    if (!animation.unposed) throw new Error('Player: the animation has no unposed frames (animate with { unposed: true })');
    this.stop();
    this.animation = animation;
    this.buffer = buffer;
    this.shape = shape ?? null;
    this.currentFrame = 0;
  }

  get take(): Animation | null {
    return this.animation;
  }

  get current(): number {
    return this.currentFrame;
  }

  get isPlaying(): boolean {
    return this.playing !== null || this.streaming !== null;
  }

  /** Show frame `frame` of the take (clamped to it). */
  show(frame: number): void {
    const a = this.animation;
    if (!a?.unposed) return;
    const n3 = a.unposed.length / a.frames;
    const f = Math.min(Math.max(0, Math.floor(frame)), a.frames - 1);
    this.currentFrame = f;
    const unposed = a.unposed.subarray(f * n3, (f + 1) * n3);
    this.view.setTongue?.(a.tongue[f] ?? 0);
    this.view.setVertices(this.shape ? this.shape(f, unposed) : unposed);
    this.view.setSpeaking?.(true);
    if (a.blendshapes) this.view.setBlendshapes?.(a.blendshapes, f);
    this.pose(a.pose.subarray(f * 6, f * 6 + 6));
    this.options.onFrame?.(f);
  }

  /**
   * Show streamed frames (live) at the model's `fps`: a batch of several (a device slower than the stream computes
   * them together) is played out frame by frame rather than jumping to its last, so a lip closure inside a batch is
   * seen. After LIVE_REST_FRAMES frames without speech the face goes back to rest, and its life (blinks, breathing)
   * with it, until speech comes again.
   */
  showLive(frames: Frames, fps: number): void {
    const now = performance.now();
    const spacing = (LIVE_SPACING * 1000) / fps;
    let due = this.liveQueue.at(-1)?.due ?? -Infinity;
    for (let f = 0; f < frames.count; f++) this.liveQueue.push({ frames, f, due: (due = Math.max(now, due + spacing)) });
    const over = this.liveQueue.length - Math.floor(LIVE_BACKLOG_MS / spacing) - 1;
    if (over > 0) {
      for (const q of this.liveQueue.splice(0, over)) this.countSpeech(q.frames, q.f);
      this.liveQueue.forEach((q, i) => (q.due = now + i * spacing));
    }
    this.liveTick ||= requestAnimationFrame(this.showDue);
  }

  /** Show the newest live frame that is due (those before it pass unseen, as on a display slower than the model's fps). */
  private showDue = (): void => {
    this.liveTick = 0;
    const now = performance.now();
    let n = 0;
    while (n < this.liveQueue.length && this.liveQueue[n].due <= now) n++;
    if (n > 0) {
      const shown = this.liveQueue.splice(0, n);
      for (const q of shown) this.countSpeech(q.frames, q.f);
      const { frames, f } = shown[n - 1];
      this.showFrame(frames, f, this.liveQuiet < LIVE_REST_FRAMES);
    }
    if (this.liveQueue.length) this.liveTick = requestAnimationFrame(this.showDue);
  };

  /** Show frame `f` of streamed `frames`; `speaking` false: the face goes back to rest (and its life with it). */
  showFrame(frames: Frames, f: number, speaking: boolean): void {
    const n3 = frames.unposed.length / frames.count;
    this.view.setTongue?.(frames.tongue[f] ?? 0);
    this.view.setVertices(frames.unposed.subarray(f * n3, (f + 1) * n3));
    this.view.setSpeaking?.(speaking);
    if (frames.blendshapes) this.view.setBlendshapes?.(frames.blendshapes, f);
    this.pose(frames.pose.subarray(f * 6, f * 6 + 6));
  }

  private countSpeech(frames: Frames, f: number): void {
    this.liveQuiet = frames.speech[f] > SPEECH_PROBABILITY ? 0 : this.liveQuiet + 1;
  }

  private pose(p: Float32Array): void {
    const s = this.unitsPerMm;
    this.view.setPose(p[0], p[1], p[2], p[3] * s, p[4] * s, p[5] * s);
  }

  /**
   * Play from `from` (default: the current frame, or the start when at the end) with the face in sync.
   * Resolves when playback ends or is stopped. `once`: to the end, whatever `loop` says.
   */
  play(from?: number, once = false): Promise<void> {
    const a = this.animation;
    if (!a || !this.buffer) return Promise.resolve();
    if (this.disposed) return Promise.reject(new Error(DISPOSED));
    this.stop();
    const start = from ?? (this.currentFrame >= a.frames - 1 ? 0 : this.currentFrame);
    this.context ??= new AudioContext();
    const context = this.context;
    // Deliberate: resume() rejects only when the context is closed, and then start() below throws with the reason.
    const resumed = context.resume().catch(() => undefined); // rejects only on a closed context; start() then throws why
    return new Promise<void>((resolve) => {
      const source = context.createBufferSource();
      source.buffer = this.buffer;
      this.output(source);
      const startedAt = context.currentTime + 0.05;
      const playing: Playing = { source, startedAt, fromFrame: start, finish: resolve };
      const ended = () => {
        if (this.playing !== playing) return;
        this.playing = null;
        if (this.loop && !once) {
          this.show(0);
          void this.play(0).then(resolve);
          return;
        }
        this.show(a.frames - 1);
        this.view.setSpeaking?.(false); // after speech, back to the face at rest
        resolve();
        this.options.onEnded?.();
      };
      // Its sound is rendered; it is heard its latency later: the last frames are shown until then (not while recorded).
      source.onended = () => {
        const lag = this.tapNode ? 0 : context.currentTime - heardTime(context);
        if (lag > 0) setTimeout(ended, 1000 * lag);
        else ended();
      };
      source.start(startedAt, start / a.fps);
      this.playing = playing;
      let last = -1;
      const tick = () => {
        if (this.playing !== playing || this.animation !== a) return;
        // What is heard now; while recorded, what goes into the recording (the tap takes the sound as it is rendered).
        const now = this.tapNode ? context.currentTime : heardTime(context);
        const f = playing.fromFrame + Math.floor((now - playing.startedAt) * a.fps);
        if (f !== last && f >= playing.fromFrame && f < a.frames) {
          last = f;
          this.show(f);
        }
        requestAnimationFrame(tick);
      };
      requestAnimationFrame(tick);
      this.watchAutoplay(resumed, () => this.playing === playing);
    });
  }

  /**
   * Streamed speech begins (player/stream-playback.ts): what played stops, and `stop` is what stop() calls until
   * streamDone(). Its sound goes out through output().
   */
  beginStream(stop: () => void): AudioContext {
    this.stop();
    this.streaming = stop;
    const context = (this.context ??= new AudioContext());
    const resumed = context.resume().catch(() => undefined); // rejects only on a closed context; start() then throws why
    this.watchAutoplay(resumed, () => this.streaming === stop);
    return context;
  }

  /** The streamed speech `stop` is over (played out, or stopped). */
  streamDone(stop: () => void): void {
    if (this.streaming !== stop) return;
    this.streaming = null;
    this.forgetGesture(); // over while its sound was held back: no gesture is waited for
  }

  /** Where sound that plays goes: the speakers at the volume, and the tap (recordVideo) as it is. */
  output(node: AudioNode): void {
    if (!this.gain) {
      this.gain = this.context!.createGain();
      this.gain.gain.value = this.level;
      this.gain.connect(this.context!.destination);
    }
    node.connect(this.gain);
    if (this.tapNode) node.connect(this.tapNode);
  }

  /** How loud the sound plays, 0 (silent: the face keeps its clock) to 1 (as it is); at once, also while it plays. */
  get volume(): number {
    return this.level;
  }
  set volume(level: number) {
    this.level = level;
    if (this.gain) this.gain.gain.value = level;
  }

  /** A context still suspended once `resumed` settles waits for a gesture (autoplay.ts), while `current()`. */
  private watchAutoplay(resumed: Promise<unknown>, current: () => boolean): void {
    this.forgetGesture();
    this.forgetGesture = resumeOnGesture(this.context!, resumed, current, this.options);
  }

  /** Create and resume the audio output now, within a person's gesture, so a take animated later may play (autoplay rules). */
  unlock(): void {
    this.context ??= new AudioContext();
    // Deliberate: resume() rejects only when the context is closed, and then play() throws with the reason.
    void this.context.resume().catch(() => undefined); // rejects only on a closed context; play() then says why
  }

  /** The sound of what plays from now on as a stream too (a recording of the take: player/record-video.ts), until untap(). */
  tap(): MediaStream {
    if (this.disposed) throw new Error(DISPOSED);
    this.context ??= new AudioContext();
    this.tapNode ??= this.context.createMediaStreamDestination();
    return this.tapNode.stream;
  }

  untap(): void {
    this.tapNode?.disconnect();
    stopTracks(this.tapNode?.stream); // (the recording's track is not left live)
    this.tapNode = null;
  }

  /** Stop playback (the face keeps the frame it shows). */
  stop(): void {
    this.forgetGesture(); // a player stopped (or removed with its element) waits for no gesture: nor keeps its view alive
    this.liveQuiet = LIVE_REST_FRAMES; // a live session after this starts at rest, whatever the last one ended on
    this.liveQueue = [];
    if (this.liveTick) cancelAnimationFrame(this.liveTick);
    this.liveTick = 0;
    const streaming = this.streaming;
    this.streaming = null;
    streaming?.();
    const p = this.playing;
    if (!p) return;
    this.playing = null;
    p.source.onended = null;
    p.source.stop();
    p.finish();
  }

  /** Stop and release the audio output. */
  dispose(): void {
    this.disposed = true; // (a recording waiting to start must not make a new context for it: play and tap refuse)
    this.stop();
    // Deliberate: closing an AudioContext fails only if it is already closed, which is the goal.
    void this.context?.close().catch(() => undefined); // fails only when already closed: the goal
    [this.context, this.gain] = [null, null];
  }
}

/**
 * <talking-face>: the whole thing as one custom element (shadow DOM); docs/embedding.md. Instances with the same model,
 * template and backend share one engine. Attributes: model, template, src, backend, autoplay, live, avatar (a glTF
 * avatar instead of the face), avatar-head-bone, avatar-facing, blendshapes, head-motion (0-3), muted, hide-status. Methods:
 * speak(audio), speakStream(options), startMicrophone(), stop(), recordVideo(). Events: ready, frame, ended, error.
 */
import { AvatarView } from '../avatar/avatar-view';
import type { GltfAvatar } from '../avatar/gltf-avatar';
import type { Animation, Backend, Frames, TalkingFaceEngine } from '../engine/engine';
import type { LiveSession } from '../engine/live';
import { avatarAttributes, backendAttribute, frameOptions, isOn, loadChange, loadKey, reflect } from './attributes';
import { makeTake, TakeError, type ElementTake } from './take';
import { shadowParts, type StatusLine } from './parts';
import { ElementStage, CONTEXT_LOST } from './stage';
import { DEFAULT_MANIFEST_URL } from '../model/manifest';
import { holdEngine, unlessAborted, type EngineHold } from './engines';
import type { PlayerView } from '../player/player';
import { SpeechStream, type MediaSpeechStream } from '../player/speech-stream';
import { checkedStreamOptions, type SpeechStreamOptions, type WrittenSpeechOptions } from '../player/stream-options';
import { listenLive } from './microphone';
import { elementStreamHost, NO_FACE, type WorkHost } from './work-host';
import { playbackFrameDetail, readyDetail, TalkingFaceError, type FrameDetail, type ReadyDetail, type TalkingFaceErrorDetail } from './events';

export type { FrameDetail, ReadyDetail, TalkingFaceErrorDetail } from './events';

/** The model an element loads when it has no `model` attribute. */
export const DEFAULT_MODEL = DEFAULT_MANIFEST_URL;

/** Where there is no DOM (a framework rendering on its server imports the library there) the element is a plain class. */
const ElementBase = (typeof HTMLElement === 'undefined' ? class {} : HTMLElement) as typeof HTMLElement;

export class TalkingFaceElement extends ElementBase {
  static observedAttributes = ['model', 'template', 'src', 'backend', 'autoplay', 'live', 'avatar', 'avatar-head-bone', 'avatar-facing', 'muted'];

  private readonly status: StatusLine;
  private readonly stage: ElementStage;
  private engine: TalkingFaceEngine | null = null;
  private loading: Promise<TalkingFaceEngine> | null = null;
  private hold: EngineHold | null = null; // on the shared engine (engines.ts): released when removed or switched
  private liveSession: LiveSession | null = null; // (not `live`: a framework would set it for the `live` attribute)
  private speech: SpeechStream | null = null; // the last speakStream()
  private computeMs = 0;
  private endings = 0; // takes that played to their end (`ended` sent): recordVideo() cancelled after one sends none again
  private audioSeconds = 0;
  private generation = 0; // bumps on stop() and on every new speak(): stale work drops its results
  private work: AbortController | null = null; // the speak() or startMicrophone() under way: stop() aborts it
  private opening: AbortController | null = null; // the last startMicrophone()'s work (`live` removed stops it)
  private playingStatus = '';
  private connected = false; // connectedCallback has run once
  private retrying = false; // the last load failed: the next to succeed shows the face itself
  private made: string[] = []; // what the face loaded or loading is made from (loadKey)
  private autoplayed = false; // this model's `src` has been autoplayed (or was not to be): another avatar does not again

  constructor() {
    super();
    const { canvas, status } = shadowParts(this);
    this.status = status;
    this.stage = new ElementStage(canvas, {
      onFrame: (f) => this.playbackFrame(f),
      onEnded: () => {
        this.status.set(this.playingStatus.replace(/^Playing/, 'Played')); // the same notes, in the past: it is over
        this.endings++; // (before: a listener that records the take counts this end as past)
        this.dispatchEvent(new CustomEvent('ended'));
      },
      // Autoplay rules: the browser starts sound only after a person's gesture on the page.
      onBlocked: () => this.status.set('Click or press a key to hear it: the browser plays sound only after a gesture.'),
      onUnblocked: () => this.status.set(this.playingStatus),
    }, (lost) => (lost ? this.fail('render', CONTEXT_LOST) : this.status.set('The face is drawn again.')));
  }

  /** Resolves with the engine once the model is loaded (rejects if it cannot be). */
  get ready(): Promise<TalkingFaceEngine> { return this.load(); }

  /** The decoder's backend in use (null before the model loads); setting it sets the `backend` attribute. */
  get backend(): Backend | null { return this.engine?.backend ?? null; }
  set backend(value: 'auto' | Backend | null) { reflect(this, 'backend', value); }

  /** The take shown (posed vertices per frame; with an avatar, its blend-shape output), e.g. to export it; null before one,
   * and once the avatar, model or template changes or the element is removed (recordVideo() has nothing to replay). */
  get currentAnimation(): Animation | null { return this.stage.player?.take ?? null; }

  /** How loud the speech plays, 0 to 1 (default 1), as a media element's `volume`: the face keeps in sync at any volume. */
  get volume(): number { return this.stage.volume; }
  set volume(level: number) { this.stage.volume = level; } // a RangeError outside 0-1
  /** Silent, the face still in sync (a page that plays the sound its own way); reflects the `muted` attribute. */
  get muted(): boolean { return this.stage.muted; }
  set muted(on: boolean) { reflect(this, 'muted', on ? '' : null); }

  /** The glTF avatar being driven (its three.js scene, naming scheme, head bone), or null. */
  get avatar(): GltfAvatar | null { return this.stage.view instanceof AvatarView ? this.stage.view.avatar : null; }
  /** Setting it sets the `avatar` attribute (its URL; null removes it), as frameworks that set properties do. */
  set avatar(url: string | null) { reflect(this, 'avatar', url); }

  connectedCallback(): void {
    // Moved within the page (disconnectedCallback kept everything): it goes on, unless changed while out of it.
    if (this.connected && (this.stage.view || this.engine || this.loading)) return this.refresh();
    [this.connected, this.retrying, this.made] = [true, false, loadKey(this, DEFAULT_MODEL)]; // this call shows the face once loaded
    void this.load().then(() => this.afterLoad(), () => undefined); // deliberate: load() has reported the failure (status line, `error` event)
  }

  disconnectedCallback(): void {
    // Moved (removed and put back in the same task, as frameworks and modals do): it goes on playing or listening.
    queueMicrotask(() => {
      if (this.isConnected) return;
      this.stop();
      this.stage.drop();
      this.letGo(); // freed ENGINE_LINGER_MS after the last element using it is gone, unless it is put back
    });
  }

  attributeChangedCallback(name: string, old: string | null, value: string | null): void {
    if (name === 'muted') this.stage.muted = isOn(value); // at once, connected or not
    // Before the first connectedCallback (an upgrade calls this first, for every attribute) that call reads them all.
    if (old === value || !this.isConnected || !this.connected) return;
    if (name === 'model' || name === 'template' || name.startsWith('avatar') || name === 'backend') {
      this.refresh();
    } else if (name === 'src' && value) { // set while the model loads: spoken once it is in
      void this.speak(value).catch(() => undefined); // speak() has reported it (status line, `error` event)
    } else if (name === 'live' && (this.engine || this.retrying)) { // (retrying: a failed load is tried again)
      if (isOn(value)) void this.startMicrophone().catch(() => undefined); // reported by fail(), as speak()
      else if (this.liveSession || (this.work && this.work === this.opening)) this.stop(); // a speak() begun since goes on
    }
  }

  /**
   * Animate and play `audio` (a Blob or File, an AudioBuffer, or a URL: same origin, or CORS-enabled). Resolves
   * when playback ends (or stop() is called); rejects with a readable Error, also sent as an error event.
   */
  async speak(audio: Blob | AudioBuffer | URL | string): Promise<void> {
    const { gen, signal } = this.begin();
    const engine = await unlessAborted(this.load(), signal);
    if (!engine || gen !== this.generation) return; // stopped (or removed) while the model loaded
    if (!this.isConnected) throw this.fail('avatar', NO_FACE, gen); // (not animated for nothing)
    let take: ElementTake;
    try {
      take = await makeTake(engine, audio, this, signal, (text, announce) => gen === this.generation && this.status.set(text, false, announce));
    } catch (e) {
      if (gen !== this.generation) return; // stopped: the abort is no failure
      throw e instanceof TakeError ? this.fail(e.stage, e.message, gen) : e;
    }
    [this.computeMs, this.audioSeconds] = [take.computeMs, take.seconds];
    const player = await this.stage.settled(); // an avatar may still be loading
    if (gen !== this.generation) return;
    if (!player) throw this.fail('avatar', this.stage.error ?? NO_FACE, gen);
    this.work = null; // animated: stop() from here stops the playback
    player.load(take.animation, take.decoded.buffer);
    player.show(0);
    this.playingStatus = take.playing;
    this.status.set(this.playingStatus);
    await player.play(0);
  }

  /**
   * Speech that arrives in pieces (a streaming text-to-speech, a voice agent): write() its PCM as it comes, end() after
   * the last; each piece is animated and played, the face in sync, a short delay after it arrives (docs/embedding.md).
   */
  speakStream(options: WrittenSpeechOptions): SpeechStream;
  speakStream(options: SpeechStreamOptions): MediaSpeechStream; // following a MediaStream (or either): no write()
  speakStream(options: SpeechStreamOptions): SpeechStream {
    let checked: ReturnType<typeof checkedStreamOptions>;
    try {
      checked = checkedStreamOptions(options); // before anything under way is stopped
    } catch (e) {
      throw this.fail('audio', (e as Error).message);
    }
    const { gen, signal } = this.begin();
    const work = this.work;
    return (this.speech = new SpeechStream(checked, elementStreamHost(this.host(gen, signal), ({ animation, buffer }) => {
      if (this.work === work) this.work = null; // played out: stop() has nothing left to stop
      [this.computeMs, this.audioSeconds] = [NaN, buffer.duration]; // (no compute time of its own)
      this.playingStatus = `Playing streamed speech (${buffer.duration.toFixed(1)} s).`; // (recordVideo() plays it again)
      this.stage.player?.load(animation, buffer); // for recordVideo()
    })));
  }

  /** What work of generation `gen` (stopped by `signal`) is lent: the model, the player, the status line, the events. */
  private host(gen: number, signal: AbortSignal): WorkHost {
    return { signal, element: this, engine: unlessAborted(this.load(), signal), player: () => this.stage.player, settled: () => this.stage.settled(), faceError: () => this.stage.error,
      current: () => gen === this.generation, status: (text) => this.status.set(text), fail: (stage, message) => this.fail(stage, message, gen),
      playing: (text) => this.status.set((this.playingStatus = text)), dispatch: (event) => this.dispatchEvent(event), halt: () => this.halt(false) };
  }

  /** Stop what this element does and claim the next generation for new work, which `signal` cancels. */
  private begin(): { gen: number; signal: AbortSignal } {
    if (this.connected && !this.isConnected) throw this.fail('avatar', NO_FACE); // removed: not loaded again for nothing
    this.halt(false);
    this.work = new AbortController();
    return { gen: this.generation, signal: this.work.signal };
  }

  /**
   * Animate a microphone live (`deviceId`: listMicrophones()'s; default the system's). Rejects (and sends an error event)
   * if it is denied or absent; one that fails or loses its sound later stops (released, the face at rest), reported.
   */
  async startMicrophone(options: { deviceId?: string } = {}): Promise<void> {
    const { gen, signal } = this.begin();
    this.opening = this.work;
    const live = await listenLive(this.host(gen, signal), (stage, message) => (this.fail(stage, message), this.halt(false)), options?.deviceId);
    if (live && gen !== this.generation) void live.stop(); // stopped as it started: the microphone released
    else if (live) [this.liveSession, this.work] = [live, null];
  }

  /** The last take replayed and recorded with its sound as a video (WebM or MP4) in real time; `signal` cancels. */
  async recordVideo(options: { signal?: AbortSignal; onProgress?: (seconds: number) => void } = {}): Promise<Blob> {
    const { engine, currentAnimation: animation, endings } = this;
    if (this.speech?.open) throw this.fail('render', 'streamed speech is playing: record once it has played (its take is then recorded)');
    if (!engine || !animation) throw this.fail('render', 'there is no take to record: speak() one first');
    return this.stage.recordVideo(engine.fps, options.signal ?? new AbortController().signal, (f) => options.onProgress?.(f / engine.fps))
      .catch((e: Error) => Promise.reject(options.signal?.aborted ? (this.endings === endings && this.rest(), e) : this.fail('render', `the video could not be made: ${e.message}`)));
  }

  /** Stop playback and the microphone; the face (or avatar) goes back to rest. */
  stop(): void { this.halt(true); }

  /** Load again what the attributes changed (loadKey: nothing if they mean the same). Another backend takes its shared
   * engine and keeps the view; `src` autoplays again for another model or template, else only if it had not yet. */
  private refresh(): void {
    const change = loadChange(this.made, (this.made = loadKey(this, DEFAULT_MODEL)));
    if (!change) return;
    if (change === 'model') this.autoplayed = false;
    this.stop();
    this.letGo();
    if (change !== 'backend') this.stage.drop();
    void this.load().then(() => this.afterLoad(!this.autoplayed), () => undefined); // deliberate: load() reports its failure
  }

  /** Stop what runs; `say`: tell it in the status line (not when new work takes its place: that work speaks). */
  private halt(say: boolean): void {
    this.generation++;
    const cancelled = this.work;
    const wasPlaying = this.stage.player?.isPlaying ?? false; // (before the abort, which stops a stream's sound)
    this.work = null;
    cancelled?.abort(); // an animation under way stops at its next chunk
    this.stage.player?.stop();
    if (wasPlaying || this.liveSession) this.rest(); // (speak() resolves on stop() too)
    if (this.liveSession) {
      const live = this.liveSession;
      this.liveSession = null;
      if (say) this.status.set('Stopped listening.'); // the microphone is released at once; the take's end follows
      void live.stop();
    } else if (say && (wasPlaying || cancelled)) this.status.set('Stopped.');
  }

  /** Back to the face at rest, and `ended`: what a take stopped before its end does. */
  private rest(): void {
    (this.stage.view as PlayerView | null)?.setSpeaking?.(false);
    this.dispatchEvent(new CustomEvent('ended'));
  }

  private load(): Promise<TalkingFaceEngine> {
    if (!this.loading) {
      const model = this.getAttribute('model')?.trim() || DEFAULT_MODEL; // (as loadKey reads it: blank is none)
      this.status.set('Loading the model…');
      const hold = (this.hold = holdEngine(model, this.getAttribute('template')?.trim() || null, backendAttribute(this.getAttribute('backend'))));
      this.loading = hold.engine.then(
        (engine) => {
          if (this.hold !== hold) return engine; // released meanwhile (removed, or another model or backend)
          this.engine = engine;
          // Not in the page (speak() or `ready` before it was added): not held, as no disconnectedCallback would let go.
          if (!this.isConnected) queueMicrotask(() => !this.isConnected && this.hold === hold && this.letGo());
          // A retry (`ready`, speak() or startMicrophone() after a failed load): no connectedCallback will show the face.
          if (this.retrying) void this.afterLoad(!this.autoplayed, !this.work); // (`live` and `src` start unless work retried)
          this.retrying = false;
          return engine;
        },
        (e: Error) => {
          if (this.hold !== hold) throw e; // superseded (another model or backend): its failure is no longer the element's
          [this.loading, this.hold, this.retrying] = [null, null, true]; // a later call retries
          throw this.fail('model', `the model could not be loaded: ${e.message}`, this.generation); // (the work waiting on it fails)
        },
      );
    }
    return this.loading;
  }

  /** Release the engine (another load takes one anew). */
  private letGo(): void {
    this.hold?.release();
    [this.hold, this.loading, this.engine, this.retrying] = [null, null, null, false];
  }

  /**
   * Show the face and say ready; then follow the microphone (`live`), or speak `src` (`autoplay`, unless `autoplay` is
   * false); `start` false: neither (a speak() or startMicrophone() that retried a failed load is under way).
   */
  private async afterLoad(autoplay = true, start = true): Promise<void> {
    const engine = this.engine;
    if (!engine || !this.isConnected) return; // removed (or reloading) while the model loaded: nothing to show or start
    if (!this.stage.view) {
      const avatar = this.getAttribute('avatar')?.trim() || null;
      if (avatar) this.status.set('Loading the avatar…');
      try {
        if (!(await this.stage.make(engine.template, engine.unitsPerMm, avatar, avatarAttributes(this)))) return; // superseded
      } catch (e) {
        this.fail(avatar ? 'avatar' : 'model', (e as Error).message);
        return;
      }
    }
    if (this.engine !== engine) return; // the backend or model changed while the view was made
    // The mouth closed at rest, not the opened template (idle life starts from it); an avatar's rest weights.
    const view = this.stage.view;
    const rest = view instanceof AvatarView ? engine.restArkit().then((w) => view.setRest(w))
      : engine.restFace().then((r) => (view as PlayerView | null)?.setRestFace?.(r));
    rest.catch((e: Error) => this.fail('inference', `the face at rest could not be computed: ${e.message}`));
    const undrawn = this.stage.undrawn && `${this.stage.undrawn}. Speech still plays, and its frames are reported`;
    this.status.set(undrawn || `Ready: ${engine.template.vertexCount} vertices, decoder ${engine.backend}.`, Boolean(undrawn));
    if (undrawn) this.dispatchEvent(new CustomEvent<TalkingFaceErrorDetail>('error', { detail: { message: undrawn, stage: 'render' } }));
    this.dispatchEvent(new CustomEvent<ReadyDetail>('ready', { detail: readyDetail(engine, this.avatar?.summary, !undrawn) }));
    const src = this.getAttribute('src');
    if (!start) return;
    this.autoplayed ||= autoplay;
    if (isOn(this.getAttribute('live'))) void this.startMicrophone().catch(() => undefined); // reported by fail()
    else if (autoplay && src && isOn(this.getAttribute('autoplay')) && !this.work) void this.speak(src).catch(() => undefined); // reported by fail()
  }

  /** A frame event for each frame shown while playing. */
  private playbackFrame(frame: number): void {
    const a = this.currentAnimation;
    if (!a || !this.engine || !this.stage.player?.isPlaying) return;
    this.dispatchEvent(new CustomEvent<FrameDetail>('frame', { detail: playbackFrameDetail(this.engine, a, frame, this.computeMs, this.audioSeconds) }));
  }

  /** Show and dispatch an error; returns it so callers can throw it. */
  private fail(stage: TalkingFaceErrorDetail['stage'], message: string, gen?: number): Error {
    if (gen === this.generation) this.work = null; // that work failed: nothing left for stop() to cancel
    this.status.set(message, true);
    this.dispatchEvent(new CustomEvent<TalkingFaceErrorDetail>('error', { detail: { message, stage } }));
    return new TalkingFaceError(stage, message);
  }
}

/**
 * <talking-face>: the whole thing as one custom element (shadow DOM). docs/embedding.md.
 *
 *   <script type="module" src="/lib/talking-face.js"></script>
 *   <talking-face src="/hello.wav" autoplay></talking-face>
 *
 * Attributes: model, template, src, backend, autoplay, live, avatar (a glTF avatar driven instead of the face),
 * avatar-head-bone, blendshapes, head-motion (0-3, default 1). Methods: speak(audio), startMicrophone(), stop().
 * Events: ready, frame, ended, error (detail.message is written for a person). Instances with the same model and backend share one engine.
 */
import { FaceView } from '../render/face-view';
import { AvatarView } from '../avatar/avatar-view';
import type { GltfAvatar } from '../avatar/gltf-avatar';
import { frameWeights } from '../avatar/weights';
import { MAX_HEAD_MOTION_SCALE, TalkingFaceEngine, type Animation, type Backend, type Frames } from '../engine/engine';
import type { LiveSession } from '../engine/live';
import { decodeAudio } from '../audio/decode';
import { openMicrophone } from '../audio/capture';
import { DEFAULT_MANIFEST_URL } from '../model/manifest';
import { sharedEngine } from './engines';
import { Player, audioNotes, SHORT_CLIP_SECONDS, type PlayerView } from '../player/player';
import type { FrameDetail, ReadyDetail, TalkingFaceErrorDetail } from './events';

export type { FrameDetail, ReadyDetail, TalkingFaceErrorDetail } from './events';

/** The model an element loads when it has no `model` attribute. */
export const DEFAULT_MODEL = DEFAULT_MANIFEST_URL;

const STYLE = `
:host { display: block; position: relative; width: 100%; aspect-ratio: 4 / 3; min-height: 160px; background: #15181d; border-radius: 8px; overflow: hidden; contain: content; }
canvas { display: block; width: 100%; height: 100%; outline: none; }
canvas:focus-visible { box-shadow: inset 0 0 0 3px #7ab8ff; }
.status { position: absolute; left: 0; right: 0; bottom: 0; margin: 0; padding: 4px 8px; font: 12px/1.4 system-ui, sans-serif; color: #dfe6ee; background: rgba(0, 0, 0, 0.45); }
.status.error { color: #ffd2d2; background: rgba(120, 0, 0, 0.6); }
:host([hide-status]) .status:not(.error) { display: none; }
`;

export class TalkingFaceElement extends HTMLElement {
  static observedAttributes = ['model', 'template', 'src', 'backend', 'autoplay', 'live', 'avatar', 'avatar-head-bone'];

  private readonly canvas: HTMLCanvasElement;
  private readonly statusLine: HTMLParagraphElement;
  private view: FaceView | AvatarView | null = null;
  private player: Player | null = null;
  private engine: TalkingFaceEngine | null = null;
  private loading: Promise<TalkingFaceEngine> | null = null;
  private live: LiveSession | null = null;
  private animation: Animation | null = null;
  private computeMs = 0;
  private audioSeconds = 0;
  private generation = 0; // bumps on stop() and on every new speak(): stale work drops its results
  private viewToken = {}; // the view being made (an avatar loads asynchronously)

  constructor() {
    super();
    const root = this.attachShadow({ mode: 'open' });
    const style = document.createElement('style');
    style.textContent = STYLE;
    this.canvas = document.createElement('canvas');
    this.canvas.setAttribute('part', 'canvas');
    this.canvas.tabIndex = 0;
    this.canvas.setAttribute('role', 'img');
    this.canvas.setAttribute('aria-label', 'Animated 3D face. Drag to orbit, scroll to zoom.');
    this.statusLine = document.createElement('p');
    this.statusLine.className = 'status';
    this.statusLine.setAttribute('part', 'status');
    this.statusLine.setAttribute('role', 'status');
    this.statusLine.setAttribute('aria-live', 'polite');
    root.append(style, this.canvas, this.statusLine);
  }

  /** Resolves with the engine once the model is loaded (rejects if it cannot be). */
  get ready(): Promise<TalkingFaceEngine> {
    return this.load();
  }

  get backend(): Backend | null {
    return this.engine?.backend ?? null;
  }

  /** The last offline animation (posed vertices per frame; with an avatar, its blend-shape output), e.g. to export it. */
  get currentAnimation(): Animation | null {
    return this.animation;
  }

  /** The glTF avatar being driven (its three.js scene, naming scheme, head bone), or null. */
  get avatar(): GltfAvatar | null {
    return this.view instanceof AvatarView ? this.view.avatar : null;
  }

  connectedCallback(): void {
    void this.load().then(
      () => this.afterLoad(),
      () => undefined, // deliberate: load() has already reported the failure (status line and `error` event)
    );
  }

  disconnectedCallback(): void {
    this.stop();
    this.viewToken = {};
    this.player?.dispose();
    this.player = null;
    this.view?.dispose();
    this.view = null;
  }

  attributeChangedCallback(name: string, old: string | null, value: string | null): void {
    if (old === value || !this.isConnected) return;
    if (name === 'model' || name === 'template' || name.startsWith('avatar')) {
      this.stop();
      this.loading = null;
      this.engine = null;
      this.viewToken = {};
      this.player?.dispose();
      this.player = null;
      this.view?.dispose();
      this.view = null;
      void this.load().then(() => this.afterLoad(), () => undefined); // deliberate: load() reports its failure
    } else if (name === 'backend' && this.engine && value) {
      this.engine.setBackend(value === 'auto' ? (this.engine.backend) : (value as Backend)).then(
        () => this.setStatus(`Decoder: ${this.engine!.backend}.`),
        (e: Error) => this.fail('model', `cannot switch to ${value}: ${e.message}`),
      );
    } else if (name === 'src' && value && this.engine) {
      // speak() reports its failure itself (fail(): the status line and an `error` event) before rejecting.
      void this.speak(value).catch(() => undefined); // speak() has reported it (status line, `error` event)
    } else if (name === 'live' && this.engine) {
      if (value !== null) void this.startMicrophone().catch(() => undefined); // reported by fail(), as speak()
      else this.stop();
    }
  }

  /**
   * Animate and play `audio` (a Blob or File, an AudioBuffer, or a URL on this page's origin). Resolves
   * when playback ends (or stop() is called); rejects with a readable Error, also sent as an error event.
   */
  async speak(audio: Blob | AudioBuffer | URL | string): Promise<void> {
    const engine = await this.load();
    this.stop();
    const gen = ++this.generation;
    let decoded;
    try {
      this.setStatus('Decoding audio…');
      let input: Blob | AudioBuffer;
      if (typeof audio === 'string' || audio instanceof URL) {
        const url = new URL(String(audio), document.baseURI);
        const res = await fetch(url).catch((e: Error) => {
          throw new Error(`could not fetch ${url.pathname}: ${e.message}`);
        });
        if (!res.ok) throw new Error(`could not fetch ${url.pathname}: HTTP ${res.status}`);
        input = await res.blob();
      } else input = audio;
      decoded = await decodeAudio(input, engine.manifest.audio.sample_rate);
    } catch (e) {
      throw this.fail('audio', `the audio could not be read: ${(e as Error).message}`);
    }
    if (gen !== this.generation) return;
    const seconds = decoded.samples.length / engine.manifest.audio.sample_rate;
    const t0 = performance.now();
    let animation: Animation, computeMs: number, speech: boolean;
    try {
      animation = await engine.animate(decoded.samples, {
        unposed: true,
        blendshapes: this.blendshapes,
        headMotionScale: this.headMotionScale,
        onProgress: (done, total) => gen === this.generation && this.setStatus(`Animating: frame ${done} of ${total}…`),
      });
      computeMs = performance.now() - t0;
      speech = await engine.restUnlessSpeech(animation); // noise, music, a tone: the face at rest
    } catch (e) {
      throw this.fail('inference', `animation failed: ${(e as Error).message}`);
    }
    if (gen !== this.generation) return;
    const notes = audioNotes(decoded.samples, seconds, speech);
    [this.computeMs, this.audioSeconds] = [computeMs, seconds];
    this.animation = animation;
    this.player?.load(animation, decoded.buffer);
    this.player?.show(0);
    const speed = seconds < SHORT_CLIP_SECONDS ? '' : `, ${(seconds / (computeMs / 1000)).toFixed(1)}x real time`;
    this.setStatus(notes.length ? `Playing: ${notes.join('; ')}.` : `Playing (${animation.frames} frames${speed} on ${engine.backend}).`);
    await this.player?.play(0);
  }

  /** Animate the microphone live. Rejects (and sends an error event) if it is denied or absent. */
  async startMicrophone(): Promise<void> {
    const engine = await this.load();
    this.stop();
    const gen = ++this.generation;
    let media: MediaStream;
    try {
      media = await openMicrophone();
    } catch (e) {
      throw this.fail('microphone', (e as Error).message);
    }
    if (gen !== this.generation) {
      for (const t of media.getTracks()) t.stop();
      return;
    }
    try {
      this.live = await engine.listen(media, (first: number, frames: Frames) => {
        if (gen !== this.generation || !this.player) return;
        const last = frames.count - 1;
        this.player.showLive(frames);
        const latency = this.live?.stream.latency;
        this.dispatchEvent(new CustomEvent<FrameDetail>('frame', {
          detail: { frame: first + last, time: (first + last) / engine.fps, mode: 'live', backend: engine.backend, latencyMs: latency?.lastMs,
            ...(frames.blendshapes && frameWeights(frames.blendshapes, last)) },
        }));
      }, { onError: (e) => this.fail('inference', `live animation stopped: ${e.message}`), blendshapes: this.blendshapes,
        headMotionScale: this.headMotionScale });
    } catch (e) {
      for (const t of media.getTracks()) t.stop();
      throw this.fail('microphone', `the microphone could not be captured: ${(e as Error).message}`);
    }
    this.setStatus(`Listening (look-ahead ${Math.round(this.live.stream.lookAheadMs)} ms, ${engine.backend})…`);
  }

  /** Stop playback and the microphone. */
  stop(): void {
    this.generation++;
    const wasPlaying = this.player?.isPlaying ?? false;
    this.player?.stop();
    if (wasPlaying) this.dispatchEvent(new CustomEvent('ended')); // speak() resolves on stop() too
    if (this.live) {
      const live = this.live;
      this.live = null;
      (this.view as PlayerView | null)?.setSpeaking?.(false); // back to the face at rest
      void live.stop().then(() => this.setStatus('Stopped listening.'));
    }
  }

  private load(): Promise<TalkingFaceEngine> {
    if (!this.loading) {
      const model = this.getAttribute('model') || DEFAULT_MODEL;
      this.setStatus('Loading the model…');
      this.loading = sharedEngine(model, this.getAttribute('template'), this.getAttribute('backend') || 'auto').then(
        (engine) => {
          this.engine = engine;
          return engine;
        },
        (e: Error) => {
          this.loading = null; // a later call retries
          throw this.fail('model', `the model could not be loaded: ${e.message}`);
        },
      );
    }
    return this.loading;
  }

  /** Frames carry ARKit weights and visemes with an avatar, or when the page asks. */
  private get blendshapes(): boolean {
    return this.hasAttribute('avatar') || this.hasAttribute('blendshapes');
  }

  /** The `head-motion` attribute for the next animation or session (one outside 0-3 warns and is ignored). */
  private get headMotionScale(): number | undefined {
    const v = this.getAttribute('head-motion')?.trim(), x = Number(v);
    if (v && Number.isFinite(x) && x >= 0 && x <= MAX_HEAD_MOTION_SCALE) return x;
    if (v) console.warn(`<talking-face> head-motion="${v}" is not a number from 0 to ${MAX_HEAD_MOTION_SCALE}; using the model's own motion (1)`);
    return undefined;
  }

  private async afterLoad(): Promise<void> {
    const engine = this.engine!;
    const avatar = this.getAttribute('avatar');
    if (!this.view) {
      const token = (this.viewToken = {});
      let view: FaceView | AvatarView;
      try {
        view = avatar ? await AvatarView.load(this.canvas, new URL(avatar, document.baseURI).href, this.getAttribute('avatar-head-bone'))
          : new FaceView(this.canvas, engine.template);
      } catch (e) {
        this.fail(avatar ? 'avatar' : 'model', `${avatar ? 'the avatar cannot be used' : 'the face cannot be drawn here (WebGL unavailable?)'}: ${(e as Error).message}`);
        return;
      }
      if (token !== this.viewToken || this.view) return view.dispose(); // superseded while the avatar loaded
      this.view = view;
      this.player = new Player(view, engine.unitsPerMm, { onFrame: (f) => this.playbackFrame(f), onEnded: () => this.dispatchEvent(new CustomEvent('ended')) });
    }
    engine.restFace().then(
      (rest) => (this.view as PlayerView | null)?.setRestFace?.(rest), // the mouth closed at rest, not the opened template; idle life starts from it
      (e: Error) => this.fail('inference', `the face at rest could not be computed: ${e.message}`),
    );
    this.setStatus(`Ready: ${engine.template.vertexCount} vertices, decoder ${engine.backend}.`);
    this.dispatchEvent(new CustomEvent<ReadyDetail>('ready', {
      detail: { backend: engine.backend, reason: engine.backendReason, vertices: engine.template.vertexCount, model: engine.manifest.model.name,
        avatar: this.avatar?.summary },
    }));
    const src = this.getAttribute('src');
    // Both report their failure themselves (fail(): the status line and an `error` event) before rejecting.
    if (this.hasAttribute('live')) void this.startMicrophone().catch(() => undefined); // reported by fail()
    else if (src && this.hasAttribute('autoplay')) void this.speak(src).catch(() => undefined); // reported by fail()
  }

  /** A frame event for each frame shown while playing. */
  private playbackFrame(frame: number): void {
    const a = this.animation;
    if (!a || !this.engine || !this.player?.isPlaying) return;
    this.dispatchEvent(new CustomEvent<FrameDetail>('frame', {
      detail: {
        frame, time: frame / a.fps, mode: 'playback', backend: this.engine.backend,
        inferenceMs: this.computeMs / a.frames,
        realTimeFactor: this.audioSeconds < SHORT_CLIP_SECONDS ? undefined : this.audioSeconds / (this.computeMs / 1000),
        ...(a.blendshapes && frameWeights(a.blendshapes, frame)),
      },
    }));
  }

  private setStatus(text: string, isError = false): void {
    this.statusLine.textContent = text;
    this.statusLine.classList.toggle('error', isError);
  }

  /** Show and dispatch an error; returns it so callers can throw it. */
  private fail(stage: TalkingFaceErrorDetail['stage'], message: string): Error {
    this.setStatus(message, true);
    this.dispatchEvent(new CustomEvent<TalkingFaceErrorDetail>('error', { detail: { message, stage } }));
    return new Error(message);
  }
}

export function defineTalkingFace(name = 'talking-face'): void {
  if (!customElements.get(name)) customElements.define(name, name === 'talking-face' ? TalkingFaceElement : class extends TalkingFaceElement {});
}

declare global {
  interface HTMLElementTagNameMap {
    'talking-face': TalkingFaceElement;
  }
}

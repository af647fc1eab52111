/**
 * What a <talking-face> shows on: its canvas, the view drawn there (the model's own face, or a glTF avatar that
 * loads asynchronously) and the player that drives it. One view at a time; a view superseded while it loads is
 * dropped quietly, its failure included (the newer one speaks for itself).
 */
import { FaceView } from '../render/face-view';
import { AvatarView } from '../avatar/avatar-view';
import type { FaceTemplate } from '../template/face-template';
import { Player, type PlayerOptions } from '../player/player';
import { newCanvas } from './parts';
import { cameraKey } from '../render/camera-keys';
import { recordTake } from '../player/record-video';
import { SoundOnlyView } from '../player/sound-only-view';
import { NO_WEBGL, webglAvailable } from '../render/software-gl';

/** What the element says when the browser takes its view's WebGL context. */
export const CONTEXT_LOST = 'the face can no longer be drawn: the browser took its WebGL context (too many 3D views on the page?); it is drawn again if the browser gives it back';

export class ElementStage {
  view: FaceView | AvatarView | SoundOnlyView | null = null;
  player: Player | null = null;
  /** Why the last view could not be made, or null. */
  error: string | null = null;
  /** Why the face is not drawn (no WebGL here: the speech plays and its frames are reported, nothing is shown), or null. */
  undrawn: string | null = null;
  private loudness = 1;
  private silenced = false;
  private token = new AbortController(); // the view being made: aborted when superseded (its avatar's download stops)
  private made: Promise<unknown> = Promise.resolve();

  /** `onContext(true)`: the browser took the view's WebGL context (it keeps 16 a page); `onContext(false)`: it gave it back. */
  constructor(private canvas: HTMLCanvasElement, private readonly events: PlayerOptions, private readonly onContext: (lost: boolean) => void = () => undefined) {}

  /**
   * Make the view on a fresh canvas (a second WebGL renderer cannot share one: parts.ts) with its player: the avatar
   * at `avatar` (a URL relative to the page) turned by `headBone`, or else the model's face. Resolves true once it is
   * shown, false if superseded meanwhile (drop(), another make(), the element removed); rejects with a message for
   * a person (kept in `error`). Where the page has no WebGL, the view draws nothing (`undrawn` says why).
   */
  async make(template: FaceTemplate, unitsPerMm: number, avatar: string | null, bound: { headBone: string | null; facing: '+z' | '-z' | undefined }): Promise<boolean> {
    this.token.abort();
    const token = (this.token = new AbortController());
    const root = this.canvas.getRootNode() as ShadowRoot; // the element's
    const canvas = newCanvas(root.host);
    const focused = root.activeElement === this.canvas;
    this.canvas.replaceWith(canvas);
    this.canvas = canvas;
    if (focused) canvas.focus(); // a keyboard user on the face while it loaded stays on it
    canvas.addEventListener('keydown', (ev) => cameraKey(ev, canvas === this.canvas && !(this.view instanceof SoundOnlyView) ? this.view : null));
    // Only while its view is shown: a dropped view's context is given up on purpose (dispose), and that is no loss.
    canvas.addEventListener('webglcontextlost', () => canvas === this.canvas && this.view && this.onContext(true));
    canvas.addEventListener('webglcontextrestored', () => canvas === this.canvas && this.view && this.onContext(false));
    this.undrawn = webglAvailable() ? null : `${avatar ? 'the avatar' : 'the face'} is not shown: ${NO_WEBGL}`;
    const made: Promise<FaceView | AvatarView | SoundOnlyView> = this.undrawn ? Promise.resolve(new SoundOnlyView()) : avatar ? AvatarView.load(canvas, new URL(avatar, document.baseURI).href, bound.headBone, { facing: bound.facing }, token.signal)
      : Promise.resolve().then(() => new FaceView(canvas, template));
    this.made = made;
    let view: FaceView | AvatarView | SoundOnlyView;
    try {
      view = await made;
    } catch (e) {
      if (token !== this.token) return false;
      this.error = `${avatar ? 'the avatar cannot be used' : 'the face cannot be drawn here (WebGL unavailable?)'}: ${(e as Error).message}`;
      throw new Error(this.error);
    }
    if (token !== this.token || this.view || !canvas.isConnected) {
      view.dispose();
      return false;
    }
    this.view = view;
    this.player = new Player(view, unitsPerMm, this.events);
    this.player.volume = this.silenced ? 0 : this.loudness;
    return true;
  }

  /** How loud the speech plays, 0 to 1 (the element's `volume`), kept for every view made; RangeError outside. */
  get volume(): number {
    return this.loudness;
  }
  set volume(level: number) {
    if (typeof level !== 'number' || !(level >= 0 && level <= 1)) throw new RangeError(`volume must be a number from 0 to 1, not ${String(level)}`);
    this.loudness = level;
    if (this.player) this.player.volume = this.silenced ? 0 : level;
  }

  /** Silent, the face still in sync with the sound it would play (the element's `muted`). */
  get muted(): boolean {
    return this.silenced;
  }
  set muted(on: boolean) {
    this.silenced = on;
    if (this.player) this.player.volume = on ? 0 : this.loudness;
  }

  /** The player once the view being made is there (an avatar still loading is waited for); null where it failed. */
  async settled(): Promise<Player | null> {
    await this.made.catch(() => undefined); // deliberate: a failed view has said why (`error`, and make() rejected)
    return this.player;
  }

  /** The take loaded in the player, played from its start and recorded with its sound (player/record-video.ts). */
  recordVideo(fps: number, signal: AbortSignal, onProgress: (frame: number) => void): Promise<Blob> {
    if (!this.view || !this.player?.take) return Promise.reject(new Error('there is no take to record: speak() one first'));
    if (this.view instanceof SoundOnlyView) return Promise.reject(new Error(this.undrawn ?? 'nothing is drawn'));
    return recordTake(this.canvas, this.view, this.player, fps, signal, onProgress);
  }

  /** Stop drawing and playing: the view and its player disposed, a view still loading not shown. */
  drop(): void {
    this.token.abort();
    [this.token, this.error, this.undrawn] = [new AbortController(), null, null];
    this.player?.dispose();
    this.player = null;
    this.view?.dispose();
    this.view = null;
  }
}

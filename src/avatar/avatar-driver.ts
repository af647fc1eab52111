/**
 * Plays the engine's output on a GltfAvatar, with no renderer and no DOM: what <talking-face avatar="..."> does to
 * its avatar (avatar-view.ts draws it), for a page that draws its own avatar in its own three.js scene.
 *
 *   const driver = new AvatarDriver(GltfAvatar.bind(gltf, 'me.glb'));
 *   driver.setRest(await engine.restArkit());
 *   const f = Math.floor(audio.currentTime * take.fps);            // each frame of the page's loop:
 *   if (f >= 0 && f < take.frames) driver.show(take, f);           // (at the audio's very end f can be take.frames)
 *   driver.update(performance.now());                              // blends and blinks; then the page renders
 *
 * Per frame it sets the avatar's morph targets (ARKit weights, or visemes) and turns its head bone by the predicted
 * head rotation. Speech blends in from the face at rest and back out to it (setSpeaking), so the head does not jump
 * at the first frame nor hold the last one, and idle blinks go on top (blinks.ts): the model does not predict them.
 * Nothing is allocated per frame.
 */
import type { BlendshapeFrames } from './weights';
import { ARKIT_NAMES, VISEME_NAMES } from './names';
import type { GltfAvatar } from './gltf-avatar';
import { Blinks } from './blinks';
import { LIVE_REST_FRAMES, SPEECH_PROBABILITY } from '../encoders/voice-activity';

/** Seconds speech takes to blend in from the rest, and back out to it (setSpeaking), as the template face's (face-view.ts). */
export const BLEND_IN_SECONDS = 0.12, BLEND_OUT_SECONDS = 0.4;

/** A frame source: an Animation (engine.animate's take) or a streamed Frames, made with `blendshapes: true`. */
export interface DrivenFrames {
  /** (frames x 6): axis-angle (radians), translation (mm); the rotation turns the head bone. */
  pose: Float32Array;
  blendshapes?: BlendshapeFrames;
}

/** Live frames: streamed Frames (engine.listen, createStream), with each frame's speech probability. */
export interface DrivenLiveFrames extends DrivenFrames {
  speech: Float32Array;
}

export class AvatarDriver {
  /** Idle blinks on top of the model's eyeBlink weights (an avatar without eyeBlink targets has none). Off for reduced motion. */
  blinking = true;
  /**
   * The head's turn goes on top of the head bone's rotation as the page's own animation (an AnimationMixer) set it
   * this frame, instead of on top of its rest: update() applies it, so call update() after the mixer's update.
   * (Without it, the page's animation and the driver each set the bone: whichever sets it last in a frame is seen.)
   */
  headOnTop = false;
  /** Whether update() turned the head last time (with headOnTop): one more update() then turns it back. */
  private headTurned = false;
  /** Live frames since speech was last heard (showLive). */
  private quiet = LIVE_REST_FRAMES;
  private readonly blinks: Blinks;
  private blink = 0;
  /** The frame last given (weights, visemes, head rotation); how much of it is shown against the rest is `speech`. */
  private readonly shown = { arkit: new Float32Array(ARKIT_NAMES.length), visemes: new Float32Array(VISEME_NAMES.length), head: new Float32Array(3) };
  private readonly scaled = { arkit: new Float32Array(ARKIT_NAMES.length), visemes: new Float32Array(VISEME_NAMES.length) };
  /** The ARKit weights of the model's face at rest (setRest; 0 until given): what the avatar shows before and after speech. */
  private readonly rest = new Float32Array(ARKIT_NAMES.length);
  /** The weight of the frame given against the rest (0: the rest alone), ramping to `target` (setSpeaking). */
  private speech = 0;
  private target = 0;
  private lastTime = -1;

  /** `now`: the clock update() will be given (ms; performance.now() by default); `random`: for the blinks (tests seed it). */
  constructor(readonly avatar: GltfAvatar, now = globalThis.performance?.now() ?? 0, random: () => number = Math.random) {
    if (typeof (avatar as Partial<GltfAvatar> | null)?.setWeights !== 'function') {
      throw new TypeError('AvatarDriver takes a GltfAvatar: new AvatarDriver(GltfAvatar.bind(gltf, name))');
    }
    this.blinks = new Blinks(now, random);
  }

  /** The speech weight now (0: the rest, 1: the frame given). */
  get speechWeight(): number {
    return this.speech;
  }

  /**
   * Show frame `frame` of a take or a streamed chunk, and start speaking if not yet (blended in over
   * BLEND_IN_SECONDS by update()); `speaking` false: go back to rest from it (as speakStream's `show` asks at a pause
   * and at the end). A take made without `blendshapes: true` is refused, saying so.
   */
  show(frames: DrivenFrames, frame: number, speaking = true): void {
    this.apply(frames, frame, 'show');
    this.setSpeaking(speaking);
  }

  /**
   * Show frame `frame` of live frames, in order as they come: as show(), but the face goes back to rest after
   * LIVE_REST_FRAMES frames without speech (a pause between phrases; a breath between words does not) and speaks
   * again when speech comes, as <talking-face live> does.
   */
  showLive(frames: DrivenLiveFrames, frame: number): void {
    this.apply(frames, frame, 'showLive');
    this.quiet = frames.speech[Math.floor(frame)] > SPEECH_PROBABILITY ? 0 : this.quiet + 1;
    this.setSpeaking(this.quiet < LIVE_REST_FRAMES);
  }

  private apply(frames: DrivenFrames, frame: number, name: string): void {
    if (!frames.blendshapes) throw new Error(`AvatarDriver.${name}: these frames have no blend-shape output: animate (or createStream, listen) with { blendshapes: true }`);
    const count = frames.pose.length / 6;
    if (!(frame >= 0 && frame < count)) throw new RangeError(`AvatarDriver.${name}: frame ${frame} is outside 0..${count - 1}`);
    const f = Math.floor(frame);
    this.setBlendshapes(frames.blendshapes, f);
    this.setPose(frames.pose[f * 6], frames.pose[f * 6 + 1], frames.pose[f * 6 + 2]);
  }

  /** Frame `frame` of the blend-shape output onto the avatar's morph targets. */
  setBlendshapes(b: BlendshapeFrames, frame: number): void {
    const { arkit, visemes } = this.shown, A = arkit.length, V = visemes.length;
    for (let k = 0; k < A; k++) arkit[k] = b.arkit[frame * A + k]; // (copied by index: a subarray view per frame is an allocation)
    for (let k = 0; k < V; k++) visemes[k] = b.visemes[frame * V + k];
    if (this.speech >= 1) this.avatar.setWeights(b.arkit, frame * ARKIT_NAMES.length, b.visemes, frame * VISEME_NAMES.length);
    else this.blend();
  }

  /** The head's rotation (axis-angle, radians, the avatar's axes): it turns the head bone. */
  setPose(rx: number, ry: number, rz: number): void {
    const h = this.shown.head; // kept for the fade to rest
    h[0] = rx;
    h[1] = ry;
    h[2] = rz;
    if (this.headOnTop) return; // update() turns it
    if (this.speech >= 1) this.avatar.setHeadRotation(rx, ry, rz);
    else this.blend();
  }

  /**
   * The weights of the model's face at rest (engine.restArkit(): what frames of silence get, e.g. mouthRollLower about
   * 0.16): shown while nothing is spoken, so that the avatar does not move when speech starts or ends in a pause.
   */
  setRest(arkit: ArrayLike<number>): void {
    if (arkit.length !== ARKIT_NAMES.length) throw new RangeError(`AvatarDriver.setRest: expected ${ARKIT_NAMES.length} ARKit weights, got ${arkit.length}`);
    this.rest.set(arkit);
    if (this.speech === 0) this.blend(); // speaking: the rest shows once speech ends
  }

  /**
   * Speech starts (true: blended in from the rest over BLEND_IN_SECONDS) or stops (false: playback stopped or ended,
   * a pause live): the face goes back to rest and the head to neutral over BLEND_OUT_SECONDS, instead of holding the
   * frame last shown (mid-word, when stopped). update() moves the blend. A show() after it speaks again: a live
   * session's stop() hands over its last frames before it resolves, so show nothing more once stopping, then call this.
   */
  setSpeaking(on: boolean): void {
    if (this.target === (on ? 1 : 0)) return;
    this.target = on ? 1 : 0;
    this.lastTime = -1;
  }

  /**
   * Move the blend and the idle blink to `now` (ms, the clock the constructor was given), once per drawn frame.
   * Returns whether the avatar changed (a page that renders only on change renders then).
   */
  update(now: number): boolean {
    let changed = false;
    if (this.speech !== this.target) {
      this.ramp(now / 1000);
      changed = true;
    }
    const blink = this.avatar.canBlink && this.blinking ? this.blinks.at(now) : 0;
    if (blink !== this.blink) {
      this.blink = blink;
      this.avatar.setIdleBlink(blink);
      changed = true;
    }
    if (this.headOnTop && (this.speech > 0 || this.headTurned)) {
      const s = this.speech, h = this.shown.head;
      this.avatar.setHeadRotation(s * h[0], s * h[1], s * h[2], true); // at speech 0, the animation's rotation alone
      this.headTurned = s > 0;
      changed = true;
    }
    return changed;
  }

  /** Back to the avatar's own neutral face, at once. */
  reset(): void {
    [this.speech, this.target, this.quiet, this.headTurned] = [0, 0, LIVE_REST_FRAMES, false];
    this.avatar.reset();
  }

  /** One step of `speech` towards `target`. */
  private ramp(seconds: number): void {
    const dt = this.lastTime < 0 ? 0 : seconds - this.lastTime;
    this.lastTime = seconds;
    const up = this.target > this.speech;
    this.speech = up ? Math.min(1, this.speech + dt / BLEND_IN_SECONDS) : Math.max(0, this.speech - dt / BLEND_OUT_SECONDS);
    if (Math.abs(this.speech - this.target) < 1e-9) this.speech = this.target; // rounding: the ramp ends where it ends
    this.blend();
  }

  /** The frame's weights and head rotation weighed by `speech` against the rest's (visemes: against viseme_sil). */
  private blend(): void {
    const s = this.speech, { arkit, visemes } = this.scaled;
    for (let k = 0; k < arkit.length; k++) arkit[k] = s * this.shown.arkit[k] + (1 - s) * this.rest[k];
    for (let k = 0; k < visemes.length; k++) visemes[k] = s * this.shown.visemes[k];
    visemes[0] += 1 - s; // viseme_sil
    this.avatar.setWeights(arkit, 0, visemes, 0);
    const h = this.shown.head;
    if (!this.headOnTop) this.avatar.setHeadRotation(s * h[0], s * h[1], s * h[2]);
  }
}

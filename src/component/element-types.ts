/**
 * The element's attributes and events as frameworks' declarations type them (talking-face/jsx for React,
 * talking-face/vue, talking-face/svelte): no framework's types here, so each of those needs only its own.
 */
import type { FrameDetail, ReadyDetail, TalkingFaceErrorDetail } from './events';

/** The element's attributes (docs/embedding.md, "Attributes"); a boolean one is on when present. */
export interface TalkingFaceAttributes {
  /** URL of the exported model's manifest (default /models/manifest.json). */
  model?: string;
  /** URL of the face template (default: the manifest's). */
  template?: string;
  /** Audio URL to speak (same origin, or CORS-enabled); null (as frameworks write it) removes the attribute. */
  src?: string | null;
  /** auto (default): WebGPU on a hardware GPU, else CPU. */
  backend?: 'auto' | 'cpu' | 'webgpu';
  autoplay?: boolean;
  /** Animate the microphone as soon as the model is ready. */
  live?: boolean;
  /** Play silently, the face still in sync (the `muted` property; `volume` sets the loudness, 0 to 1). */
  muted?: boolean;
  'hide-status'?: boolean;
  /** URL of a glTF avatar (.glb, .gltf or .vrm) to drive instead of the built-in face; null: the built-in face. */
  avatar?: string | null;
  'avatar-head-bone'?: string;
  /** Which way the avatar's face looks: +z (glTF's convention) or -z; default: -z for a VRM 0.x file, else +z. */
  'avatar-facing'?: '+z' | '-z';
  /** `frame` events carry ARKit weights, visemes and the head rotation without an avatar. */
  blendshapes?: boolean;
  /** How far the head's own motion turns the head, 0 to 3 (default 1). */
  'head-motion'?: number | `${number}`;
}

/**
 * The element's events as React 19 and Svelte 5 listen to them on a custom element: `on` and the event's name as it
 * is (`onframe`, not `onFrame`). React's own `onError` and `onEnded` are for media and images: on this element they
 * would never be called, so talking-face/jsx leaves them out.
 */
export interface TalkingFaceEventProps {
  onready?: (event: CustomEvent<ReadyDetail>) => void;
  onframe?: (event: CustomEvent<FrameDetail>) => void;
  onended?: (event: Event) => void;
  onerror?: (event: CustomEvent<TalkingFaceErrorDetail>) => void;
}

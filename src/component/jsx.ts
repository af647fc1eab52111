/**
 * JSX declarations for <talking-face> in React (and the frameworks that read React's JSX types): attributes typed as
 * docs/embedding.md lists them, `ref` typed as TalkingFaceElement. Opt in once per project with
 * `import type {} from 'talking-face/jsx'` (or `"types": ["talking-face/jsx"]` in tsconfig.json). A module of its own
 * because it augments 'react': the package's other declarations must not need @types/react.
 */
import type * as React from 'react';
import type { TalkingFaceElement } from './talking-face';
import type { FrameDetail, ReadyDetail, TalkingFaceErrorDetail } from './events';

/** The element's attributes (docs/embedding.md, "Attributes"); a boolean one is on when present. */
export interface TalkingFaceAttributes {
  /** URL of the exported model's manifest (default /models/manifest.json). */
  model?: string;
  /** URL of the face template (default: the manifest's). */
  template?: string;
  /** Audio URL to speak (same origin, or CORS-enabled). */
  src?: string;
  /** auto (default): WebGPU on a hardware GPU, else CPU. */
  backend?: 'auto' | 'cpu' | 'webgpu';
  autoplay?: boolean;
  /** Animate the microphone as soon as the model is ready. */
  live?: boolean;
  'hide-status'?: boolean;
  /** URL of a glTF avatar (.glb or .gltf) to drive instead of the built-in face. */
  avatar?: string;
  'avatar-head-bone'?: string;
  /** Which way the avatar's face looks: +z (glTF's convention, default) or -z (VRM 0.x). */
  'avatar-facing'?: '+z' | '-z';
  /** `frame` events carry ARKit weights, visemes and the head rotation without an avatar. */
  blendshapes?: boolean;
  /** How far the head's own motion turns the head, 0 to 3 (default 1). */
  'head-motion'?: number | `${number}`;
}

/**
 * The element's events as React 19 listens to them on a custom element: `on` and the event's name as it is
 * (`onframe`, not `onFrame`). React's own `onError` and `onEnded` are for media and images: on this element they
 * would never be called, so its type leaves them out.
 */
export interface TalkingFaceEventProps {
  onready?: (event: CustomEvent<ReadyDetail>) => void;
  onframe?: (event: CustomEvent<FrameDetail>) => void;
  onended?: (event: Event) => void;
  onerror?: (event: CustomEvent<TalkingFaceErrorDetail>) => void;
}

type ReactProps = React.DetailedHTMLProps<React.HTMLAttributes<TalkingFaceElement>, TalkingFaceElement>;

declare module 'react' {
  namespace JSX {
    interface IntrinsicElements {
      'talking-face': Omit<ReactProps, 'onError' | 'onErrorCapture' | 'onEnded' | 'onEndedCapture'> & TalkingFaceAttributes & TalkingFaceEventProps;
    }
  }
}

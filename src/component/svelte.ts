/**
 * Svelte 5 declarations for <talking-face>: its attributes typed as docs/embedding.md lists them, its events as
 * Svelte 5's event attributes (`onready={...}`, `onframe`, `onended`, `onerror`) with their details, and
 * `bind:this` as TalkingFaceElement, for svelte-check. Opt in once per project with
 * `import type {} from 'talking-face/svelte'` (in src/app.d.ts, say). A module of its own because it augments
 * 'svelte/elements': the package's other declarations must not need Svelte.
 */
import type { HTMLAttributes } from 'svelte/elements';
import type { TalkingFaceElement } from './talking-face';
import type { TalkingFaceAttributes, TalkingFaceEventProps } from './element-types';

export type { TalkingFaceAttributes, TalkingFaceEventProps };

declare module 'svelte/elements' {
  interface SvelteHTMLElements {
    'talking-face': Omit<HTMLAttributes<TalkingFaceElement>, 'onerror' | 'onended'> & TalkingFaceAttributes & TalkingFaceEventProps;
  }
}

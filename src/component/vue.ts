/**
 * Vue declarations for <talking-face>: its attributes typed as docs/embedding.md lists them, its events as Vue's
 * `@ready` / `@frame` / `@ended` / `@error` listen to them, for vue-tsc's template checks. Opt in once per project
 * with `import type {} from 'talking-face/vue'` (in env.d.ts, say). A module of its own because it augments 'vue':
 * the package's other declarations must not need Vue. Vue must also be told that talking-face is an element, not
 * one of its components (compilerOptions.isCustomElement; docs/embedding.md, "Vue"), which no declaration can say.
 */
import type { DefineComponent } from 'vue';
import type { TalkingFaceAttributes } from './element-types';
import type { FrameDetail, ReadyDetail, TalkingFaceErrorDetail } from './events';

export type { TalkingFaceAttributes };

/** The element's events as Vue types a listener (`@frame` is the prop `onFrame`). */
export interface TalkingFaceVueEvents {
  onReady?: (event: CustomEvent<ReadyDetail>) => void;
  onFrame?: (event: CustomEvent<FrameDetail>) => void;
  onEnded?: (event: Event) => void;
  onError?: (event: CustomEvent<TalkingFaceErrorDetail>) => void;
}

/** `hide-status` -> `hideStatus`: how vue-tsc reads a hyphenated attribute of a component's. */
type Camel<S extends string> = S extends `${infer Head}-${infer Tail}` ? `${Head}${Capitalize<Camel<Tail>>}` : S;

/**
 * The attributes as vue-tsc checks them: hyphenated ones by their camelCase name. Write them hyphenated in a template
 * all the same (`:hide-status="hidden"`): Vue sets a name the element has no property for as an attribute, as written,
 * and HTML lowercases `hideStatus` to an attribute the element does not read.
 */
export type TalkingFaceVueAttributes = { [K in keyof TalkingFaceAttributes as Camel<K>]: TalkingFaceAttributes[K] };

declare module 'vue' {
  interface GlobalComponents {
    'talking-face': DefineComponent<TalkingFaceVueAttributes & TalkingFaceVueEvents>;
  }
}

/**
 * JSX declarations for <talking-face> in React (and the frameworks that read React's JSX types): attributes typed as
 * docs/embedding.md lists them, `ref` typed as TalkingFaceElement. Opt in once per project with
 * `import type {} from 'talking-face/jsx'` (or `"types": ["talking-face/jsx"]` in tsconfig.json). A module of its own
 * because it augments 'react': the package's other declarations must not need @types/react.
 */
import type * as React from 'react';
import type { TalkingFaceElement } from './talking-face';
import type { TalkingFaceAttributes, TalkingFaceEventProps } from './element-types';

export type { TalkingFaceAttributes, TalkingFaceEventProps };

type ReactProps = React.DetailedHTMLProps<React.HTMLAttributes<TalkingFaceElement>, TalkingFaceElement>;

declare module 'react' {
  namespace JSX {
    interface IntrinsicElements {
      'talking-face': Omit<ReactProps, 'onError' | 'onErrorCapture' | 'onEnded' | 'onEndedCapture'> & TalkingFaceAttributes & TalkingFaceEventProps;
    }
  }
}

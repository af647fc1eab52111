/** The library build's entry (dist/lib/talking-face.js): defines <talking-face> and exports the library API. */
import { defineTalkingFace } from './talking-face';

export * from '../index';
export { TalkingFaceElement, defineTalkingFace, DEFAULT_MODEL, type ReadyDetail, type FrameDetail, type TalkingFaceErrorDetail } from './talking-face';

defineTalkingFace();

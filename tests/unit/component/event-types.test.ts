/**
 * The element's events are typed for TypeScript pages (src/component/index.ts, TalkingFaceEventMap): the listeners
 * docs/embedding.md writes compile as written, with `e.detail` typed. Checked by the typecheck suite (tsc -p .);
 * the declarations the library build ships are emitted from the same source.
 */
import { describe, expectTypeOf, it } from 'vitest';
import type { TalkingFaceElement, ReadyDetail, FrameDetail, TalkingFaceErrorDetail } from '../../../src/component/index';

/** The docs' "Use" listeners, as written (never run: the types are what is tested). */
function listen(face: TalkingFaceElement): void {
  face.addEventListener('ready', (e) => console.log('decoder', e.detail.backend, e.detail.reason));
  face.addEventListener('frame', (e) => console.log(e.detail.frame, e.detail.inferenceMs ?? e.detail.latencyMs));
  face.addEventListener('error', (e) => console.log(e.detail.message));
  face.addEventListener('ended', (e) => expectTypeOf(e).toEqualTypeOf<Event>());
  face.addEventListener('ready', (e) => expectTypeOf(e.detail).toEqualTypeOf<ReadyDetail>());
  face.addEventListener('frame', (e) => expectTypeOf(e.detail).toEqualTypeOf<FrameDetail>());
  face.addEventListener('error', (e) => expectTypeOf(e.detail).toEqualTypeOf<TalkingFaceErrorDetail>());
  face.addEventListener('keydown', (e) => expectTypeOf(e).toEqualTypeOf<KeyboardEvent>()); // the DOM's own stay typed
  const onReady = (e: CustomEvent<ReadyDetail>) => e.detail.vertices;
  face.addEventListener('ready', onReady);
  face.removeEventListener('ready', onReady);
  face.addEventListener('some-page-event', () => undefined); // any other name still takes a plain listener
}

describe('event types', () => {
  it('types each event\'s detail (compiled by the typecheck suite)', () => {
    expectTypeOf(listen).parameter(0).toEqualTypeOf<TalkingFaceElement>();
  });
});

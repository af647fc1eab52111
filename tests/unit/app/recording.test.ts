/** The demo's microphone take (src/app/recording.ts): what its status lines say while recording. */
import { describe, expect, it } from 'vitest';
import { Recording } from '../../../src/app/recording';
import type { TalkingFaceEngine } from '../../../src/engine/engine';
import type { LiveOptions } from '../../../src/engine/live';

/** An engine whose listen() hands back a live session the test sets the skipped frames of, and keeps its options. */
function fakeEngine(): { engine: TalkingFaceEngine; options: () => LiveOptions; skip: (n: number) => void } {
  let options: LiveOptions = {};
  const stream = { skippedFrames: 0 };
  const engine = {
    resetTimes: () => undefined,
    listen: (_media: MediaStream, _onFrames: unknown, o: LiveOptions) => { options = o; return Promise.resolve({ stream }); },
  } as unknown as TalkingFaceEngine;
  return { engine, options: () => options, skip: (n) => { stream.skippedFrames = n; } };
}

const media = { getTracks: () => [] } as unknown as MediaStream;

describe('Recording.slowNote', () => {
  it('says once that the device fell behind', async () => {
    const f = fakeEngine();
    const r = await Recording.start(f.engine, () => Promise.resolve(media), () => undefined, () => undefined);
    expect(r.slowNote()).toBeNull();
    f.skip(4);
    expect(r.slowNote()).toContain('slower than real time');
    expect(r.slowNote()).toBeNull();
  });

  it('stays quiet after a warning, which the status line keeps', async () => {
    const f = fakeEngine();
    const told: [string, boolean][] = [];
    const r = await Recording.start(f.engine, () => Promise.resolve(media), () => undefined, (text, isError) => told.push([text, isError]));
    f.options().onInterrupted!(new Error('the microphone stopped sending sound') as never);
    f.skip(4);
    expect(r.slowNote()).toBeNull();
    expect(told).toEqual([['Recording, but the microphone stopped sending sound. Stop recording keeps what was heard.', true]]);
  });
});

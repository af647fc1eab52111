/**
 * resumeOnGesture (src/player/autoplay.ts), on a stand-in context and document: a context the autoplay rules hold
 * back is resumed at the next gesture, once; one that runs, or a wait forgotten, leaves no listener; a closed one
 * leaves none either.
 */
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { AUTOPLAY_WAIT_MS, resumeOnGesture } from '../../../src/player/autoplay';
import { FakeContext, installAudioClock } from '../helpers/audio-clock';

/** A document that counts its listeners. */
class Doc extends EventTarget {
  listening = 0;
  override addEventListener(...a: Parameters<EventTarget['addEventListener']>) {
    this.listening++;
    super.addEventListener(...a);
  }
  override removeEventListener(...a: Parameters<EventTarget['removeEventListener']>) {
    this.listening--;
    super.removeEventListener(...a);
  }
}
let doc: Doc;

beforeEach(() => {
  installAudioClock();
  vi.useFakeTimers();
  vi.stubGlobal('document', (doc = new Doc()));
});
afterEach(() => {
  vi.useRealTimers();
  vi.unstubAllGlobals();
});

function held(): FakeContext {
  FakeContext.heldBack = true;
  const context = new FakeContext();
  context.resume = vi.fn(context.resume.bind(context));
  return context;
}

describe('resumeOnGesture', () => {
  it('a context still suspended after the wait is resumed at the next gesture: blocked, then unblocked, listeners gone', async () => {
    const context = held();
    const calls: string[] = [];
    resumeOnGesture(context as unknown as AudioContext, context.resume(), () => true,
      { onBlocked: () => calls.push('blocked'), onUnblocked: () => calls.push('unblocked') });
    await vi.advanceTimersByTimeAsync(AUTOPLAY_WAIT_MS - 10);
    expect(calls).toEqual([]); // not yet: it may still start by itself
    await vi.advanceTimersByTimeAsync(20);
    expect(calls).toEqual(['blocked']);
    expect(doc.listening).toBeGreaterThan(0);
    context.allow(); // the browser lets it run once a person has acted...
    doc.dispatchEvent(new Event('pointerdown')); // ...and the listener asks it to
    await vi.advanceTimersByTimeAsync(0);
    expect(context.state).toBe('running');
    expect(calls).toEqual(['blocked', 'unblocked']);
    expect(doc.listening).toBe(0);
  });

  it('waits for no gesture where the context runs, where the wait is forgotten, or where the sound is no longer wanted', async () => {
    const running = new FakeContext();
    const onBlocked = vi.fn();
    resumeOnGesture(running as unknown as AudioContext, running.resume(), () => true, { onBlocked });
    const forgotten = held();
    resumeOnGesture(forgotten as unknown as AudioContext, forgotten.resume(), () => true, { onBlocked })();
    const stale = held();
    resumeOnGesture(stale as unknown as AudioContext, stale.resume(), () => false, { onBlocked });
    await vi.advanceTimersByTimeAsync(2 * AUTOPLAY_WAIT_MS);
    expect(onBlocked).not.toHaveBeenCalled();
    expect(doc.listening).toBe(0);
  });

  it('a context closed while it waits stops waiting at the next gesture', async () => {
    const context = held();
    const onUnblocked = vi.fn();
    resumeOnGesture(context as unknown as AudioContext, context.resume(), () => true, { onUnblocked });
    await vi.advanceTimersByTimeAsync(2 * AUTOPLAY_WAIT_MS);
    expect(doc.listening).toBeGreaterThan(0);
    await context.close();
    doc.dispatchEvent(new Event('keydown'));
    await vi.advanceTimersByTimeAsync(0);
    expect(doc.listening).toBe(0);
    expect(onUnblocked).not.toHaveBeenCalled();
  });

  it("a page's onBlocked that throws is reported and the wait goes on; one click's several events unblock once", async () => {
    const reported: unknown[] = [];
    vi.stubGlobal('reportError', (e: unknown) => reported.push(e));
    const context = held();
    const onUnblocked = vi.fn();
    resumeOnGesture(context as unknown as AudioContext, context.resume(), () => true, { onUnblocked, onBlocked: () => {
      throw new Error('the page broke');
    } });
    await vi.advanceTimersByTimeAsync(2 * AUTOPLAY_WAIT_MS);
    expect(reported).toEqual([new Error('the page broke')]);
    expect(doc.listening).toBeGreaterThan(0);
    context.allow();
    for (const g of ['pointerdown', 'pointerup', 'touchend']) doc.dispatchEvent(new Event(g)); // one tap
    await vi.advanceTimersByTimeAsync(0);
    expect(onUnblocked).toHaveBeenCalledTimes(1);
    expect(doc.listening).toBe(0);
  });

  it('a context that runs by itself after the wait (an output slow to start) was no block: unblocked, listeners gone', async () => {
    const context = held();
    const calls: string[] = [];
    resumeOnGesture(context as unknown as AudioContext, context.resume(), () => true,
      { onBlocked: () => calls.push('blocked'), onUnblocked: () => calls.push('unblocked') });
    await vi.advanceTimersByTimeAsync(AUTOPLAY_WAIT_MS + 10);
    expect(calls).toEqual(['blocked']);
    expect(doc.listening).toBeGreaterThan(0);
    context.allow(); // it starts, no gesture made
    expect(calls).toEqual(['blocked', 'unblocked']);
    expect(doc.listening).toBe(0);
  });
});

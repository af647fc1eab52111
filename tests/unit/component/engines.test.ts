/**
 * The engines <talking-face> elements share (src/component/engines.ts): one load per model, template and backend,
 * disposed ENGINE_LINGER_MS after the last element holding it lets go, unless one takes it back meanwhile.
 */
import { afterEach, describe, expect, it, vi } from 'vitest';
import { TalkingFaceEngine } from '../../../src/engine/engine';
import { ENGINE_LINGER_MS, holdEngine } from '../../../src/component/engines';

afterEach(() => {
  vi.restoreAllMocks();
  vi.useRealTimers();
});

const fakeEngine = () => ({ dispose: vi.fn(async () => undefined) }) as unknown as TalkingFaceEngine & { dispose: ReturnType<typeof vi.fn> };

describe('holdEngine', () => {
  it('loads once per model, template and backend, and passes each what the element asked for', async () => {
    const fake = fakeEngine();
    const load = vi.spyOn(TalkingFaceEngine, 'load').mockResolvedValue(fake);
    const a = holdEngine('/models/manifest.json', null, 'auto');
    const b = holdEngine('/models/manifest.json', null, 'auto');
    const c = holdEngine('/models/manifest.json', null, 'cpu');
    const d = holdEngine('/models/manifest.json', '/other/template.json', 'auto');
    expect(a.engine).toBe(b.engine);
    expect(c.engine).not.toBe(a.engine);
    expect(d.engine).not.toBe(a.engine);
    expect(load).toHaveBeenCalledTimes(3);
    expect(load.mock.calls.map(([o]) => [o!.templateUrl, o!.backend])).toEqual([[undefined, 'auto'], [undefined, 'cpu'], ['/other/template.json', 'auto']]);
    expect(await a.engine).toBe(fake);
    for (const h of [a, b, c, d]) h.release();
  });

  it('forgets a failed load, so a later element tries again', async () => {
    const load = vi.spyOn(TalkingFaceEngine, 'load').mockRejectedValueOnce(new Error('offline')).mockResolvedValue(fakeEngine());
    const failed = holdEngine('/failing/manifest.json', null, 'auto');
    await expect(failed.engine).rejects.toThrow('offline');
    failed.release();
    await Promise.resolve();
    const again = holdEngine('/failing/manifest.json', null, 'auto');
    await expect(again.engine).resolves.toBeDefined();
    expect(load).toHaveBeenCalledTimes(2);
    again.release();
  });

  it('disposes an engine once the last hold is released and the linger has passed; a hold taken back in time keeps it', async () => {
    vi.useFakeTimers();
    const first = fakeEngine();
    const second = fakeEngine();
    const load = vi.spyOn(TalkingFaceEngine, 'load').mockResolvedValueOnce(first).mockResolvedValueOnce(second);
    const a = holdEngine('/linger/manifest.json', null, 'auto');
    const b = holdEngine('/linger/manifest.json', null, 'auto');
    await a.engine;
    a.release();
    a.release(); // once is enough: b still holds it
    await vi.advanceTimersByTimeAsync(ENGINE_LINGER_MS * 2);
    expect(first.dispose).not.toHaveBeenCalled();
    b.release();
    await vi.advanceTimersByTimeAsync(ENGINE_LINGER_MS / 2);
    const moved = holdEngine('/linger/manifest.json', null, 'auto'); // an element put back within the linger
    expect(await moved.engine).toBe(first);
    await vi.advanceTimersByTimeAsync(ENGINE_LINGER_MS * 2);
    expect(first.dispose).not.toHaveBeenCalled();
    moved.release();
    await vi.advanceTimersByTimeAsync(ENGINE_LINGER_MS + 1);
    expect(first.dispose).toHaveBeenCalledTimes(1);
    // Gone: the next element loads anew.
    const later = holdEngine('/linger/manifest.json', null, 'auto');
    expect(await later.engine).toBe(second);
    expect(load).toHaveBeenCalledTimes(2);
    later.release();
  });

  it('a linger begun while a load was failing leaves the engine loaded again for that model alone', async () => {
    vi.useFakeTimers();
    let fail!: (e: Error) => void;
    const again = fakeEngine();
    vi.spyOn(TalkingFaceEngine, 'load').mockReturnValueOnce(new Promise((_, reject) => { fail = reject; })).mockResolvedValue(again);
    const gone = holdEngine('/flaky/manifest.json', null, 'auto');
    gone.release(); // removed while it loads: the linger starts
    fail(new Error('offline'));
    await expect(gone.engine).rejects.toThrow('offline');
    const back = holdEngine('/flaky/manifest.json', null, 'auto'); // put back, within the linger: loads anew
    expect(await back.engine).toBe(again);
    await vi.advanceTimersByTimeAsync(ENGINE_LINGER_MS + 1); // the first linger ends
    const third = holdEngine('/flaky/manifest.json', null, 'auto');
    expect(third.engine).toBe(back.engine); // still shared, not loaded a third time
    back.release();
    third.release();
    await vi.advanceTimersByTimeAsync(ENGINE_LINGER_MS + 1);
    expect(again.dispose).toHaveBeenCalledTimes(1); // and freed once the last hold goes
  });
});

/** The engines <talking-face> elements share (src/component/engines.ts): one load per model, template and backend. */
import { afterEach, describe, expect, it, vi } from 'vitest';
import { TalkingFaceEngine } from '../../../src/engine/engine';
import { sharedEngine } from '../../../src/component/engines';

afterEach(() => vi.restoreAllMocks());

describe('sharedEngine', () => {
  it('loads once per model, template and backend, and passes each what the element asked for', async () => {
    const fake = {} as TalkingFaceEngine;
    const load = vi.spyOn(TalkingFaceEngine, 'load').mockResolvedValue(fake);
    const a = sharedEngine('/models/manifest.json', null, 'auto');
    const b = sharedEngine('/models/manifest.json', null, 'auto');
    const c = sharedEngine('/models/manifest.json', null, 'cpu');
    const d = sharedEngine('/models/manifest.json', '/other/template.json', 'auto');
    expect(a).toBe(b);
    expect(c).not.toBe(a);
    expect(d).not.toBe(a);
    expect(load).toHaveBeenCalledTimes(3);
    expect(load.mock.calls.map(([o]) => [o!.templateUrl, o!.backend])).toEqual([[undefined, 'auto'], [undefined, 'cpu'], ['/other/template.json', 'auto']]);
    expect(await a).toBe(fake);
  });

  it('forgets a failed load, so a later element tries again', async () => {
    const load = vi.spyOn(TalkingFaceEngine, 'load').mockRejectedValueOnce(new Error('offline')).mockResolvedValue({} as TalkingFaceEngine);
    await expect(sharedEngine('/failing/manifest.json', null, 'auto')).rejects.toThrow('offline');
    await Promise.resolve();
    await expect(sharedEngine('/failing/manifest.json', null, 'auto')).resolves.toBeDefined();
    expect(load).toHaveBeenCalledTimes(2);
  });
});

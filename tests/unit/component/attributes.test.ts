import { afterEach, describe, expect, it, vi } from 'vitest';
import { audioInput, avatarAttributes, backendAttribute, frameOptions, headMotionAttribute, isOn, loadChange, loadKey } from '../../../src/component/attributes';

describe('<talking-face> attributes', () => {
  afterEach(() => vi.unstubAllGlobals());

  it('backend: auto, cpu or webgpu; anything else warns and means auto', () => {
    const warn = vi.spyOn(console, 'warn').mockImplementation(() => undefined);
    expect(backendAttribute(null)).toBe('auto');
    expect(backendAttribute(' ')).toBe('auto');
    expect(backendAttribute('cpu')).toBe('cpu');
    expect(backendAttribute('webgpu')).toBe('webgpu');
    expect(warn).not.toHaveBeenCalled();
    expect(backendAttribute('gpu')).toBe('auto');
    expect(warn).toHaveBeenCalledWith(expect.stringContaining('backend="gpu"'));
    warn.mockRestore();
  });

  it('what the face is made from: values that mean the same load nothing again; a change says what to load', () => {
    const el = (attrs: Record<string, string>) => ({ getAttribute: (n: string) => attrs[n] ?? null }) as unknown as Element;
    const key = (attrs: Record<string, string>) => loadKey(el(attrs), '/models/manifest.json');
    const plain = key({});
    expect(loadChange(plain, key({ model: '', backend: 'auto' }))).toBeNull(); // (absent and these mean the same)
    expect(loadChange(plain, key({ model: ' /models/manifest.json ' }))).toBeNull();
    expect(loadChange(plain, key({ backend: 'cpu' }))).toBe('backend');
    expect(loadChange(plain, key({ avatar: '/a.glb', backend: 'cpu' }))).toBe('avatar');
    expect(loadChange(plain, key({ 'avatar-facing': '-z' }))).toBe('avatar');
    expect(loadChange(plain, key({ template: '/t.json', avatar: '/a.glb' }))).toBe('model');
    expect(loadChange(plain, key({ model: '/other/manifest.json' }))).toBe('model');
  });

  it('a boolean attribute is on when present and not "false" (React 18 writes autoplay={false} as "false")', () => {
    expect([null, 'false', ' FALSE '].map(isOn)).toEqual([false, false, false]);
    expect(['', 'true', 'autoplay', 'yes'].map(isOn)).toEqual([true, true, true, true]);
    const el = (attrs: Record<string, string>) => ({ getAttribute: (n: string) => attrs[n] ?? null, hasAttribute: (n: string) => n in attrs }) as unknown as Element;
    expect(frameOptions(el({ blendshapes: 'false' })).blendshapes).toBe(false);
    expect(frameOptions(el({ blendshapes: '' })).blendshapes).toBe(true);
  });

  it('avatar-facing: +z or -z; absent, left to the file (VRM 0.x: -z); anything else warns and is left to the file', () => {
    const warn = vi.spyOn(console, 'warn').mockImplementation(() => undefined);
    const el = (attrs: Record<string, string>) => ({ getAttribute: (n: string) => attrs[n] ?? null }) as unknown as Element;
    expect(avatarAttributes(el({}))).toEqual({ headBone: null, facing: undefined });
    expect(avatarAttributes(el({ 'avatar-facing': '-z', 'avatar-head-bone': 'Skull' }))).toEqual({ headBone: 'Skull', facing: '-z' });
    expect(avatarAttributes(el({ 'avatar-facing': ' +z ' })).facing).toBe('+z');
    expect(warn).not.toHaveBeenCalled();
    expect(avatarAttributes(el({ 'avatar-facing': 'back' })).facing).toBe(undefined);
    expect(warn).toHaveBeenCalledWith(expect.stringContaining('avatar-facing="back" is not +z or -z'));
    warn.mockRestore();
  });

  it('head-motion: a number from 0 to 3, else a warning and the model\'s own', () => {
    const warn = vi.spyOn(console, 'warn').mockImplementation(() => undefined);
    expect(headMotionAttribute('0.5')).toBe(0.5);
    expect(headMotionAttribute(null)).toBeUndefined();
    expect(headMotionAttribute('4')).toBeUndefined();
    expect(headMotionAttribute('lively')).toBeUndefined();
    expect(warn).toHaveBeenCalledTimes(2);
    warn.mockRestore();
  });

  it('a URL that cannot be fetched is named in the message, with its host when it is another origin\'s', async () => {
    vi.stubGlobal('document', { baseURI: 'http://page.test/demo/' });
    vi.stubGlobal('location', { origin: 'http://page.test' });
    vi.stubGlobal('fetch', async (url: URL) => {
      if (url.pathname === '/missing.wav') return new Response('', { status: 404 });
      throw new TypeError('Failed to fetch');
    });
    await expect(audioInput('/missing.wav')).rejects.toThrow('could not fetch /missing.wav: HTTP 404');
    await expect(audioInput('https://elsewhere.test/a.wav')).rejects.toThrow('could not fetch https://elsewhere.test/a.wav: Failed to fetch');
    await expect(audioInput('/Grüße 日本語.wav')).rejects.toThrow('could not fetch /Grüße 日本語.wav: Failed to fetch'); // as written, not %-encoded
    await expect(audioInput('/100%E0.wav')).rejects.toThrow('could not fetch /100%E0.wav: Failed to fetch'); // not a name's %-sequence: as given
    const blob = new Blob(['x']);
    expect(await audioInput(blob)).toBe(blob);
  });

  it('anything else is refused with a message that says what speak() takes and what it got', async () => {
    const takes = 'speak() takes a Blob or File, an AudioBuffer, or a URL';
    for (const [input, got] of [[42, 'number'], [undefined, 'undefined'], [null, 'null'], ['', 'an empty string'], [{}, 'Object'], [new Float32Array(4), 'Float32Array']] as const) {
      await expect(audioInput(input as never)).rejects.toThrow(`${takes} (got ${got})`);
    }
  });
});

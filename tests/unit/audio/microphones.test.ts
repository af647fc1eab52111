/**
 * Choosing a microphone (src/audio/capture.ts): listMicrophones() lists the audio inputs a page may open, and
 * openMicrophone(deviceId) opens that one and no other, with a message a person can act on when it is gone.
 */
import { afterEach, describe, expect, it, vi } from 'vitest';
import { listMicrophones, openMicrophone, MicrophoneError } from '../../../src/audio/capture';

type Device = { kind: string; deviceId: string; label: string };

/** A browser whose mediaDevices lists `devices` and whose getUserMedia records its constraints (or throws `fails`). */
function browser(devices: Device[] | Error, fails?: string) {
  const asked: MediaStreamConstraints[] = [];
  vi.stubGlobal('navigator', {
    mediaDevices: {
      enumerateDevices: async () => { if (devices instanceof Error) throw devices; return devices; },
      getUserMedia: async (c: MediaStreamConstraints) => {
        asked.push(c);
        if (fails) throw new DOMException('', fails);
        return { getTracks: () => [] };
      },
    },
  });
  return asked;
}

afterEach(() => vi.unstubAllGlobals());

describe('listMicrophones', () => {
  it('lists the audio inputs with ids, named by the browser or by their place', async () => {
    browser([
      { kind: 'audioinput', deviceId: 'default', label: 'Default - Headset' },
      { kind: 'videoinput', deviceId: 'cam', label: 'Camera' },
      { kind: 'audioinput', deviceId: 'a1', label: 'Headset' },
      { kind: 'audiooutput', deviceId: 'o1', label: 'Speakers' },
      { kind: 'audioinput', deviceId: 'a2', label: '' },
    ]);
    expect(await listMicrophones()).toEqual([
      { deviceId: 'default', label: 'Default - Headset' },
      { deviceId: 'a1', label: 'Headset' },
      { deviceId: 'a2', label: 'Microphone 2' },
    ]);
  });

  it('lists nothing where the browser hides the inputs (no ids before the page may use one) or cannot list them', async () => {
    browser([{ kind: 'audioinput', deviceId: '', label: '' }]);
    expect(await listMicrophones()).toEqual([]);
    browser(new DOMException('', 'NotAllowedError') as unknown as Error);
    expect(await listMicrophones()).toEqual([]);
    vi.stubGlobal('navigator', {});
    expect(await listMicrophones()).toEqual([]);
  });
});

describe('openMicrophone', () => {
  it("asks for the chosen microphone exactly, with the capture's raw settings; without one, for the system's", async () => {
    const asked = browser([]);
    await openMicrophone('a1');
    await openMicrophone();
    expect(asked[0].audio).toEqual({ deviceId: { exact: 'a1' }, channelCount: 1, echoCancellation: false, noiseSuppression: false, autoGainControl: false });
    expect(asked[1].audio).not.toHaveProperty('deviceId');
    expect(asked[1].audio).toMatchObject({ channelCount: 1, echoCancellation: false });
  });

  it('says the chosen microphone is not connected, where without a choice it says none was found', async () => {
    for (const name of ['OverconstrainedError', 'NotFoundError']) {
      browser([], name);
      await expect(openMicrophone('gone')).rejects.toThrow(/the chosen microphone is not connected; plug it back in, or choose another/);
      await expect(openMicrophone()).rejects.toThrow(/no microphone was found/);
    }
    browser([], 'NotAllowedError');
    await expect(openMicrophone('a1')).rejects.toThrow(/access was denied/);
  });

  it('refuses an id that is not a non-empty string before asking the browser', async () => {
    const asked = browser([]);
    for (const bad of ['', 5, null]) {
      const e = await openMicrophone(bad as unknown as string).catch((err: Error) => err);
      expect(e).toBeInstanceOf(MicrophoneError);
      expect((e as Error).message).toMatch(/deviceId must be a microphone's id/);
    }
    expect(asked).toHaveLength(0);
  });
});

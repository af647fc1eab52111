/** <talking-face>'s startMicrophone(): the microphone opened and animated live, its frames shown as they come. */
import type { Frames } from '../engine/frames';
import type { LiveSession } from '../engine/live';
import { openMicrophone, stopTracks } from '../audio/capture';
import { frameOptions } from './attributes';
import { liveFrameDetail, type FrameDetail, type TalkingFaceErrorDetail } from './events';
import { NO_FACE, type WorkHost } from './work-host';

/**
 * Open the microphone and animate it live: the session, or null when the work was stopped meanwhile (the microphone
 * then closed again). `lost`: listening failed or lost its sound later; `deviceId`: which microphone (default: the
 * system's). Rejects (reported) if the microphone cannot be used.
 */
export async function listenLive(host: WorkHost, lost: (stage: TalkingFaceErrorDetail['stage'], message: string) => void, deviceId?: string): Promise<LiveSession | null> {
  const engine = await host.engine;
  if (!engine || !host.current()) return null; // stopped (or removed) while the model loaded: the microphone stays closed
  const shown = await host.settled(); // an avatar may still be loading
  if (!host.current()) return null;
  if (!shown) throw host.fail('avatar', host.faceError() ?? NO_FACE); // not in the page, or no avatar: the microphone is not opened for nothing
  let media: MediaStream;
  try {
    media = await openMicrophone(deviceId);
  } catch (e) {
    if (!host.current()) return null; // stopped (or removed) while the browser asked: not a failure
    throw host.fail('microphone', (e as Error).message);
  }
  const close = () => stopTracks(media);
  if (!host.current()) return close(), null; // stopped while the browser asked
  let live: LiveSession | null = null;
  try {
    live = await engine.listen(media, (first: number, frames: Frames) => {
      const player = host.player();
      if (!host.current() || !player) return;
      player.showLive(frames, engine.fps);
      host.dispatch(new CustomEvent<FrameDetail>('frame', { detail: liveFrameDetail(engine, first, frames, live?.stream) }));
    }, { onError: (e) => host.current() && lost('inference', `live animation stopped: ${e.message}`), keepAudio: false,
      onInterrupted: (e) => host.current() && lost('microphone', `listening stopped: ${e.message}`),
      ...frameOptions(host.element) });
  } catch (e) {
    close();
    if (!host.current()) return null; // stopped meanwhile: not a failure
    throw host.fail('microphone', `the microphone could not be captured: ${(e as Error).message}`);
  }
  if (!host.current()) { // stopped while the capture started
    void live.stop();
    close();
    return null;
  }
  host.status(`Listening (look-ahead ${Math.round(live.stream.lookAheadMs)} ms, ${engine.backend})…`);
  return live;
}

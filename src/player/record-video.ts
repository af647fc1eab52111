/**
 * The take as a video to share (the demo's Export video, the element's recordVideo()): the face's canvas as it plays the take from the start, with the take's sound,
 * recorded by the browser (MediaRecorder: WebM with VP9 or VP8 and Opus, or MP4 where a browser records only that).
 * It records in real time, so it takes as long as the take (and half a second more, for the face to go back to
 * rest); what the face's canvas shows is what is recorded (pose arrows, colours, the idle life; not the ground
 * truth's view beside it), drawn even while scrolled out of sight. The file has no duration in its header (as
 * MediaRecorder writes it): players learn the length as they play it. Nothing leaves the page: the file is made
 * in the browser and saved by the visitor.
 */
import type { Player } from './player';
import { stopTracks } from '../audio/capture';

/** Containers and codecs tried in order (the first the browser records is used). */
export const VIDEO_TYPES = ['video/webm;codecs=vp9,opus', 'video/webm;codecs=vp8,opus', 'video/webm', 'video/mp4'];
/** How long the recording goes on after the take ends: the face blends back to rest (face-view.ts: 0.4 s). */
const TAIL_MS = 500;

/** Playback of the take was stopped before its end (Pause, a seek, another clip): the recording is dropped. */
export class PlaybackStopped extends Error {
  constructor() {
    super('the take\'s playback was stopped before its end, so no video was saved');
  }
}

/** The type this browser records video in, or null where it cannot. */
export function videoType(): string | null {
  if (typeof MediaRecorder === 'undefined' || typeof HTMLCanvasElement.prototype.captureStream !== 'function') return null;
  return VIDEO_TYPES.find((t) => MediaRecorder.isTypeSupported(t)) ?? null;
}

/**
 * Play the player's take from its first frame on `canvas` and record both; resolves with the video. `signal`
 * cancels (the promise rejects with its reason); playback stopped by anything else rejects too (the video would
 * be cut short). `onProgress` is told the frame shown, a few times a second.
 */
export async function recordTake(canvas: HTMLCanvasElement, view: { recording: boolean }, player: Player, fps: number,
  signal: AbortSignal, onProgress: (frame: number) => void): Promise<Blob> {
  const type = videoType();
  if (!type) throw new Error('this browser cannot record video (it has no MediaRecorder for WebM or MP4)');
  const frames = player.take?.frames ?? 0;
  if (!frames) throw new Error('there is no take to record');
  signal.throwIfAborted();
  const chunks: Blob[] = [];
  const stopPlaying = () => player.stop();
  const progress = setInterval(() => onProgress(player.current), 250);
  let video: MediaStream | null = null, recorder: MediaRecorder | null = null;
  view.recording = true; // drawn even where scrolled out of sight (else the video has no picture)
  try {
    player.stop(); // a playback under way would draw its frames over the first one until play() below
    player.show(0); // the first frame the recorder sees is the take's first, not whatever was shown
    // (a hidden tab draws no frames: the signal still cancels this wait)
    await new Promise<void>((r) => {
      const go = (): void => (signal.removeEventListener('abort', go), r());
      requestAnimationFrame(() => requestAnimationFrame(go));
      signal.addEventListener('abort', go, { once: true });
    });
    signal.throwIfAborted();
    video = canvas.captureStream(fps);
    recorder = new MediaRecorder(new MediaStream([...video.getVideoTracks(), ...player.tap().getAudioTracks()]),
      { mimeType: type, videoBitsPerSecond: 4_000_000 });
    recorder.ondataavailable = (e) => e.data.size > 0 && chunks.push(e.data);
    signal.addEventListener('abort', stopPlaying, { once: true });
    recorder.start(1000);
    await player.play(0, true); // (to the end, looping or not)
    signal.throwIfAborted();
    if (player.current < frames - 1) throw new PlaybackStopped();
    await new Promise((r) => setTimeout(r, TAIL_MS));
    signal.throwIfAborted();
  } finally {
    clearInterval(progress);
    signal.removeEventListener('abort', stopPlaying);
    const r = recorder;
    if (r && r.state !== 'inactive') await new Promise((done) => { r.onstop = done; r.stop(); }); // its last data comes first
    player.untap();
    view.recording = false;
    stopTracks(video);
  }
  const file = new Blob(chunks, { type: type.split(';')[0] });
  if (file.size === 0) throw new Error('the browser recorded nothing (is the face drawn on this page?)');
  return file;
}

/**
 * The sound of a MediaStream (a voice agent's WebRTC track, another page's audio) as pieces for speakStream({ media }):
 * captured at MEDIA_RATE through an AudioWorklet, the stream's own tracks left alone.
 */
import { AudioCapture } from '../audio/capture';

/** The rate a MediaStream's sound is captured and played at. */
export const MEDIA_RATE = 48000;
/** Its pieces' length (s): what a piece waits for before it is played and animated. */
export const MEDIA_PIECE_SECONDS = 0.05;

/** A MediaStream being followed: stop() ends it after its last piece, leaving the stream's tracks running. */
export interface MediaFollower {
  stop(): Promise<void>;
}

/** Why `media` cannot be followed, or null: it must be a MediaStream with an audio track that has not ended. */
export function mediaProblem(media: unknown): string | null {
  if (typeof MediaStream === 'undefined' || !(media instanceof MediaStream)) return 'media must be a MediaStream (a WebRTC track\'s stream, getUserMedia\'s, captureStream()\'s)';
  if (!media.getAudioTracks().some((t) => t.readyState === 'live')) return 'the MediaStream has no audio track that is still live';
  return null;
}

/**
 * Follow `media`'s sound: `onPiece` gets mono pieces at MEDIA_RATE, `onEnded` is called once its audio tracks end (or
 * the browser stops the audio). Chromium delivers a remote WebRTC stream's sound to Web Audio only while a media
 * element plays it too: a muted one does so here (it makes no sound).
 */
export async function followMedia(media: MediaStream, onPiece: (samples: Float32Array) => void, onEnded: () => void): Promise<MediaFollower> {
  const sink = document.createElement('audio');
  sink.muted = true;
  sink.srcObject = media;
  // Deliberate: a muted element may always play; where it is refused anyway, a local stream still delivers its sound.
  void sink.play().catch(() => undefined); // (a remote one may then be silent, which the face shows at rest)
  let capture: AudioCapture;
  try {
    capture = await AudioCapture.start(media, MEDIA_RATE, onPiece, { block: Math.round(MEDIA_PIECE_SECONDS * MEDIA_RATE), onInterrupted: onEnded });
  } catch (e) {
    sink.srcObject = null;
    throw e;
  }
  return {
    stop: async () => {
      await capture.stop(false);
      sink.srcObject = null;
    },
  };
}

/**
 * Where the face cannot be drawn (no WebGL: render/software-gl.ts), a view that draws nothing: its Player still plays
 * the speech and reports each frame on time (the element's frame events, with their ARKit weights and visemes, for a
 * page that shows them its own way).
 */
import type { PlayerView } from './player';

export class SoundOnlyView implements PlayerView {
  setVertices(): void {
    // nothing is drawn
  }

  setPose(): void {
    // nothing is drawn
  }

  dispose(): void {
    // nothing was made
  }
}

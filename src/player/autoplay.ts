/**
 * Autoplay rules: a browser holds an audio context's sound back (the context stays suspended) until a person clicks
 * or presses a key on the page. The Player (the element's) and speakStream(engine)'s own context wait for that
 * gesture and resume then; the face follows the context's clock, so it waits too.
 */

/** How long a resumed audio context may take to run before it counts as held back by the autoplay rules. */
export const AUTOPLAY_WAIT_MS = 300;
/** The events that count as a person's gesture for the autoplay rules. */
const GESTURES = ['pointerdown', 'pointerup', 'keydown', 'touchend'] as const;

export interface GestureWait {
  /** Called when the sound is found held back (the context still suspended once `resumed` settled or the wait passed). */
  onBlocked?: () => void;
  /** Called when a gesture resumed it, if `current()` still holds. */
  onUnblocked?: () => void;
}

/**
 * Once `resumed` (the context's resume()) settles or AUTOPLAY_WAIT_MS pass, a context still suspended is resumed at
 * the next gesture, while `current()` holds. Returns what removes the listeners (call it when the sound is no longer
 * wanted: stopped, disposed); they also go at the first gesture after the context runs or closes, or as soon as it
 * runs by itself (an output slow to start, a Bluetooth device waking, was no autoplay block: onUnblocked then too).
 */
export function resumeOnGesture(context: AudioContext, resumed: Promise<unknown>, current: () => boolean, wait: GestureWait = {}): () => void {
  let [forgotten, listening] = [false, false];
  const resume = () => {
    void context.resume().then(() => {
      if (forgotten) return; // (pointerdown, pointerup and touchend of one click each ask: said once)
      forget();
      if (current()) wait.onUnblocked?.();
    }, forget); // rejects only on a closed context: nothing left to play
  };
  const forget = () => {
    forgotten = true;
    if (listening) for (const g of GESTURES) document.removeEventListener(g, resume, true);
    listening = false;
    context.removeEventListener('statechange', ranByItself);
  };
  const ranByItself = () => {
    if (forgotten || context.state !== 'running') return;
    const told = listening;
    forget();
    if (told && current()) wait.onUnblocked?.();
  };
  context.addEventListener('statechange', ranByItself);
  void Promise.race([resumed, new Promise((r) => setTimeout(r, AUTOPLAY_WAIT_MS))]).then(() => {
    if (forgotten || !current() || context.state !== 'suspended') return;
    listening = true;
    for (const g of GESTURES) document.addEventListener(g, resume, true);
    try {
      wait.onBlocked?.();
    } catch (e) {
      reportError(e); // the page's callback: its error is the page's, and the wait goes on
    }
  });
  return forget;
}

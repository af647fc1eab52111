/**
 * The demo's microphone choice: a list beside Record of the audio inputs, the choice kept for the next visit, the list
 * following microphones plugged in and out. Browsers list them only once the page has been allowed a microphone: until
 * then the list holds the default and the one chosen on an earlier visit, and it is filled when a recording opens one.
 * A chosen microphone that is listed as gone shows as the default until it comes back; one asked for while the list
 * is hidden that turns out not to be connected is recorded from the default instead (and asked for again next time).
 */
import { MicrophoneError, SYSTEM_ENTRY, listMicrophones, openMicrophone } from '../audio/capture';

const KEY = 'talking-face:microphone';

export class MicrophoneChoice {
  private wanted: string;
  private blind = false; // the earlier choice is offered without the browser listing it

  constructor(private readonly select: HTMLSelectElement) {
    this.wanted = read();
    select.addEventListener('change', () => {
      write((this.wanted = select.value));
      select.title = select.selectedOptions[0]?.text ?? '';
    });
    navigator.mediaDevices?.addEventListener?.('devicechange', () => void this.refresh());
    void this.refresh();
  }

  /** The chosen microphone's id, or undefined for the system's default. */
  get deviceId(): string | undefined {
    return this.select.value || undefined;
  }

  /** Open the chosen microphone; the list is filled again after (its names come once the page may use one). */
  async open(): Promise<MediaStream> {
    const blind = this.blind && this.deviceId !== undefined;
    try {
      return await openMicrophone(this.deviceId);
    } catch (e) {
      if (!blind || !(e instanceof MicrophoneError && e.notConnected)) throw e;
      return await openMicrophone(); // the one chosen before is not there: the default (the list then shows it so)
    } finally {
      void this.refresh();
    }
  }

  /** List the inputs again (their names come once the page may use a microphone). */
  async refresh(): Promise<void> {
    const inputs = await listMicrophones();
    const system = inputs.find((d) => d.deviceId === 'default');
    const own = inputs.filter((d) => !SYSTEM_ENTRY.test(d.deviceId));
    const options = [new Option(system ? `default (${system.label.replace(/^Default\s*-\s*/i, '')})` : 'default', '')];
    for (const d of own) options.push(new Option(d.label, d.deviceId));
    // Nothing listed: the browser hides the inputs until the page may use one; the earlier choice is still asked for.
    const hidden = inputs.length === 0 && this.wanted !== '';
    if (hidden) options.push(new Option('the one chosen before', this.wanted));
    this.blind = hidden;
    this.select.replaceChildren(...options);
    this.select.value = hidden || own.some((d) => d.deviceId === this.wanted) ? this.wanted : '';
    this.select.title = this.select.selectedOptions[0]?.text ?? '';
  }
}

function read(): string {
  try {
    return localStorage.getItem(KEY) ?? '';
  } catch {
    return ''; // storage refused (a sandboxed frame, privacy settings): the choice lasts for this visit only
  }
}

function write(deviceId: string): void {
  try {
    if (deviceId) localStorage.setItem(KEY, deviceId);
    else localStorage.removeItem(KEY);
  } catch {
    // storage refused (a sandboxed frame, privacy settings): the choice lasts for this visit only
  }
}

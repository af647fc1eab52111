/**
 * The part of the browser's FileReader that three.js's GLTFExporter uses (readAsArrayBuffer, readAsDataURL of a
 * Blob), for Node: the test avatars and the .glb export are written there too (scripts/make-avatars.ts, tests).
 */
class NodeFileReader {
  result: ArrayBuffer | string | null = null;
  onloadend: (() => void) | null = null;
  onload: (() => void) | null = null;

  readAsArrayBuffer(blob: Blob): void {
    void blob.arrayBuffer().then((b) => this.done(b));
  }

  readAsDataURL(blob: Blob): void {
    void blob.arrayBuffer().then((b) => this.done(`data:${blob.type || 'application/octet-stream'};base64,${Buffer.from(b).toString('base64')}`));
  }

  private done(result: ArrayBuffer | string): void {
    this.result = result;
    this.onload?.();
    this.onloadend?.();
  }
}

export function installFileReader(): void {
  (globalThis as { FileReader?: unknown }).FileReader ??= NodeFileReader;
}

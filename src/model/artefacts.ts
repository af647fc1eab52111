/**
 * Fetching what the exporter wrote: the manifest, each runtime file checked against the manifest's SHA-256,
 * and the face template the model was trained on. Every failure is a ModelLoadError written for a person.
 */
import { checkManifest, DEFAULT_MANIFEST_URL, type Manifest } from './manifest';
import { loadTemplate, type FaceTemplate } from '../template/face-template';
import { checkedStallSeconds, fetchBody, StalledError, type FetchBodyOptions } from './fetch-body';

export class ModelLoadError extends Error {
  override name = 'ModelLoadError';
}

export interface ArtefactOptions {
  /** URL of models/manifest.json (default DEFAULT_MANIFEST_URL, against the page). */
  manifestUrl?: string | URL;
  /** The manifest, when the caller has already fetched it (from manifestUrl). */
  manifest?: Manifest;
  /** URL of the face template (default: the manifest's). */
  templateUrl?: string | URL;
  /** The face template, when the caller has loaded it or is loading it (it must be the manifest's). */
  template?: FaceTemplate | Promise<FaceTemplate>;
  fetch?: typeof fetch;
  /**
   * A download (the manifest, the template, a runtime file) that brings nothing for this many seconds fails, naming
   * it (default 30), rather than wait forever on a stalled connection; a slow one that keeps coming is waited for.
   */
  stallSeconds?: number;
}

export { STALL_SECONDS } from './fetch-body';

/** `url`'s bytes, or a ModelLoadError naming `what` (missing, unreachable, or stalled for `stallSeconds`). */
async function fetchNamed(url: URL, what: string, options: FetchBodyOptions): Promise<ArrayBuffer> {
  const body = await fetchBody(url, options).catch((e: Error) => {
    throw new ModelLoadError(e instanceof StalledError ? `${what} stalled: ${e.message} (${url})` : `could not fetch ${what} (${url}): ${e.message}`);
  });
  if (!body.ok) throw new ModelLoadError(`${what} is missing (HTTP ${body.status} for ${url})`);
  return body.bytes;
}

/** Where the face template is when the manifest cannot be read (the exporter's layout), so a page can still show a face. */
export const DEFAULT_TEMPLATE_URL = '/models/template/template.json';

export function resolveManifestUrl(url: string | URL | undefined): URL {
  return new URL(String(url ?? DEFAULT_MANIFEST_URL), globalThis.location?.href ?? 'file:///');
}

/** The manifest at `url`, checked (ModelLoadError: missing, unreachable, stalled for `stallSeconds`, or unreadable). */
export async function fetchManifest(url: string | URL | undefined, fetchFn: typeof fetch = fetch.bind(globalThis), stallSeconds?: number): Promise<{ manifest: Manifest; manifestUrl: URL }> {
  if (stallSeconds !== undefined) checkedStallSeconds(stallSeconds); // (a RangeError as it is, not as a failed download)
  const manifestUrl = resolveManifestUrl(url);
  const body = await fetchBody(manifestUrl, { fetch: fetchFn, stallSeconds }).catch((e: Error) => {
    throw new ModelLoadError(`could not fetch the model manifest ${manifestUrl}: ${e.message}`);
  });
  if (!body.ok) throw new ModelLoadError(`could not fetch the model manifest ${manifestUrl}: HTTP ${body.status}`);
  const text = new TextDecoder().decode(body.bytes);
  if (/^\s*</.test(text)) {
    throw new ModelLoadError(`the model manifest ${manifestUrl} is an HTML page, not the manifest: no manifest.json there (hosts send their index page for a missing file); serve the build's models/ folder there, or give the manifest's URL (TalkingFaceEngine.load({ manifestUrl }), or the element's model attribute)`);
  }
  try {
    return { manifest: checkManifest(JSON.parse(text)), manifestUrl };
  } catch (e) {
    throw new ModelLoadError(`the model manifest ${manifestUrl} is unreadable: ${(e as Error).message}`);
  }
}

/** The face template's URL: the caller's, else the manifest's (relative to the manifest). */
export function templateUrlOf(manifest: Manifest, manifestUrl: URL, templateUrl?: string | URL): URL {
  return templateUrl ? new URL(String(templateUrl), globalThis.location?.href ?? manifestUrl) : new URL(manifest.template.path, manifestUrl);
}

export async function sha256Hex(bytes: ArrayBuffer): Promise<string> {
  return Array.from(new Uint8Array(await crypto.subtle.digest('SHA-256', bytes)), (b) => b.toString(16).padStart(2, '0')).join('');
}

/** The manifest, with the template and every runtime file on their way (each checked when it arrives). */
export interface ArrivingArtefacts {
  manifest: Manifest;
  manifestUrl: URL;
  template: Promise<FaceTemplate>;
  /** The runtime files' bytes by manifest key, each as soon as it has arrived and matched its SHA-256. */
  files: Record<string, Promise<ArrayBuffer>>;
}

/**
 * The manifest, then every file fetched in parallel: the caller can start on a file (e.g. an ONNX session) while the
 * others are still arriving. Every promise must be awaited, or handed to one that is.
 */
export async function fetchArtefacts(options: ArtefactOptions = {}): Promise<ArrivingArtefacts> {
  const fetchFn = options.fetch ?? fetch.bind(globalThis);
  if (options.stallSeconds !== undefined) checkedStallSeconds(options.stallSeconds);
  const { manifest, manifestUrl } = options.manifest
    ? { manifest: checkManifest(options.manifest), manifestUrl: resolveManifestUrl(options.manifestUrl) }
    : await fetchManifest(options.manifestUrl, fetchFn, options.stallSeconds);
  const file = async (key: string): Promise<ArrayBuffer> => {
    const url = new URL(manifest.files[key], manifestUrl);
    const bytes = await fetchNamed(url, `model file ${manifest.files[key]}`, { fetch: fetchFn, stallSeconds: options.stallSeconds });
    if ((await sha256Hex(bytes)) !== manifest.sha256[key]) throw new ModelLoadError(`model file ${manifest.files[key]} is corrupt or from another export (SHA-256 mismatch)`);
    return bytes;
  };
  const template = (options.template
    ? Promise.resolve(options.template)
    : loadTemplate(templateUrlOf(manifest, manifestUrl, options.templateUrl), fetchFn, options.stallSeconds).catch((e: Error) => {
      throw new ModelLoadError(`the face template could not be loaded: ${e.message}`);
    })).then((t) => {
    if (t.id !== manifest.template.id) {
      throw new ModelLoadError(`the model was trained on the face template "${manifest.template.id}" and cannot drive "${t.id}" (every template needs its own trained model)`);
    }
    return t;
  });
  return { manifest, manifestUrl, template, files: Object.fromEntries(manifest.runtime_files.map((k) => [k, file(k)])) };
}

/**
 * Fetching what the exporter wrote: the manifest, each runtime file checked against the manifest's SHA-256,
 * and the face template the model was trained on. Every failure is a ModelLoadError written for a person.
 */
import { checkManifest, DEFAULT_MANIFEST_URL, type Manifest } from './manifest';
import { loadTemplate, type FaceTemplate } from '../template/face-template';

export class ModelLoadError extends Error {
  override name = 'ModelLoadError';
}

export interface ModelArtefacts {
  manifest: Manifest;
  manifestUrl: URL;
  template: FaceTemplate;
  /** The runtime files' bytes by manifest key (content_encoder, hierarchical, pose_conv, pose_lstm, decoder_weights). */
  files: Record<string, ArrayBuffer>;
}

export interface ArtefactOptions {
  /** URL of models/manifest.json (default DEFAULT_MANIFEST_URL, against the page). */
  manifestUrl?: string | URL;
  /** The manifest, when the caller has already fetched it (from manifestUrl). */
  manifest?: Manifest;
  /** URL of the face template (default: the manifest's). */
  templateUrl?: string | URL;
  /** The face template, when the caller has already loaded it (it must be the manifest's). */
  template?: FaceTemplate;
  fetch?: typeof fetch;
}

/** Where the face template is when the manifest cannot be read (the exporter's layout), so a page can still show a face. */
export const DEFAULT_TEMPLATE_URL = '/models/template/template.json';

export function resolveManifestUrl(url: string | URL | undefined): URL {
  return new URL(String(url ?? DEFAULT_MANIFEST_URL), globalThis.location?.href ?? 'file:///');
}

/** The manifest at `url`, checked. */
export async function fetchManifest(url: string | URL | undefined, fetchFn: typeof fetch = fetch.bind(globalThis)): Promise<{ manifest: Manifest; manifestUrl: URL }> {
  const manifestUrl = resolveManifestUrl(url);
  const res = await fetchFn(manifestUrl).catch((e: Error) => {
    throw new ModelLoadError(`could not fetch the model manifest ${manifestUrl}: ${e.message}`);
  });
  if (!res.ok) throw new ModelLoadError(`could not fetch the model manifest ${manifestUrl}: HTTP ${res.status}`);
  try {
    return { manifest: checkManifest(await res.json()), manifestUrl };
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

/** Everything the engine needs, fetched in parallel and checked. */
export async function loadArtefacts(options: ArtefactOptions = {}): Promise<ModelArtefacts> {
  const fetchFn = options.fetch ?? fetch.bind(globalThis);
  const { manifest, manifestUrl } = options.manifest
    ? { manifest: checkManifest(options.manifest), manifestUrl: resolveManifestUrl(options.manifestUrl) }
    : await fetchManifest(options.manifestUrl, fetchFn);
  const file = async (key: string): Promise<ArrayBuffer> => {
    const url = new URL(manifest.files[key], manifestUrl);
    const r = await fetchFn(url);
    if (!r.ok) throw new ModelLoadError(`model file ${manifest.files[key]} is missing (HTTP ${r.status} for ${url})`);
    const bytes = await r.arrayBuffer();
    if ((await sha256Hex(bytes)) !== manifest.sha256[key]) throw new ModelLoadError(`model file ${manifest.files[key]} is corrupt or from another export (SHA-256 mismatch)`);
    return bytes;
  };
  const templatePromise = options.template
    ? Promise.resolve(options.template)
    : loadTemplate(templateUrlOf(manifest, manifestUrl, options.templateUrl), fetchFn).catch((e: Error) => {
      throw new ModelLoadError(`the face template could not be loaded: ${e.message}`);
    });
  const [template, ...bytes] = await Promise.all([templatePromise, ...manifest.runtime_files.map(file)]);
  if (template.id !== manifest.template.id) {
    throw new ModelLoadError(`the model was trained on the face template "${manifest.template.id}" and cannot drive "${template.id}" (every template needs its own trained model)`);
  }
  return { manifest, manifestUrl, template, files: Object.fromEntries(manifest.runtime_files.map((k, i) => [k, bytes[i]])) };
}

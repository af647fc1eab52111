/**
 * A glTF avatar's nodes and bytes as gltf-avatar.ts and face-binding.ts need them: the error for a file that cannot
 * be used, the bytes of a file given, the folder a .gltf's files are read from, the head bone, and the rotation of a
 * node's parent relative to the avatar's root; and a .glb's JSON edited (the VRM files this project writes).
 */
import * as THREE from 'three';

export class AvatarLoadError extends Error {
  override name = 'AvatarLoadError';
}

/** The file's bytes as an ArrayBuffer of their own (a view's bytes copied out), or a TypeError saying what came. */
export function bufferOf(data: ArrayBuffer | ArrayBufferView, source: string): ArrayBuffer {
  if (data instanceof ArrayBuffer) return data;
  if (ArrayBuffer.isView(data)) return new Uint8Array(data.buffer, data.byteOffset, data.byteLength).slice().buffer;
  const what = data === null ? 'null' : typeof data === 'object' ? (data as object).constructor?.name ?? 'an object' : typeof data;
  throw new TypeError(`GltfAvatar.parse(${source}): give the file's bytes (an ArrayBuffer or a Uint8Array), not ${what}` +
    (what === 'Blob' || what === 'File' ? ' (await its arrayBuffer() first)' : ''));
}

/** The folder a .gltf's external files are read from ('' for a blob: or data: URL, which has none). */
export function folderOf(source: string): string {
  try {
    const url = new URL(source, globalThis.location?.href ?? 'file:///');
    return url.protocol === 'blob:' || url.protocol === 'data:' ? '' : new URL('.', url).href;
  } catch {
    return ''; // deliberate: a name that is no URL has no folder; an embedded .glb needs none
  }
}

const sceneWorld = new THREE.Quaternion();
const parentWorld = new THREE.Quaternion();

/** The rotation of the head's parent relative to the avatar's root (gltf.scene), from their world rotations now. */
export function parentInScene(head: THREE.Object3D, scene: THREE.Object3D): THREE.Quaternion {
  if (!head.parent) return parentWorld.identity();
  head.parent.getWorldQuaternion(parentWorld);
  scene.getWorldQuaternion(sceneWorld);
  return parentWorld.premultiply(sceneWorld.invert()); // scene^-1 * parent
}

/** The head bone: the named one, else a bone (or node) named Head / head, else one whose name ends in "head". */
export function findHead(scene: THREE.Object3D, source: string, name?: string | null): THREE.Object3D | null {
  const nodes: THREE.Object3D[] = [];
  scene.traverse((o) => nodes.push(o));
  if (name) {
    // three.js's loader spells node names its own way (`mixamorig:Head` -> `mixamorigHead`): either spelling is found.
    const sanitised = THREE.PropertyBinding.sanitizeNodeName(name);
    const found = nodes.find((o) => o.name === name) ?? nodes.find((o) => o.name === sanitised);
    if (!found) {
      const bones = nodes.filter((o) => (o as THREE.Bone).isBone).map((o) => o.name);
      const named = bones.length ? bones : nodes.map((o) => o.name).filter(Boolean);
      throw new AvatarLoadError(`${source} has no node named "${name}" (the head bone asked for: avatar-head-bone, or bind's headBone); ` +
        `its ${bones.length ? 'bones' : 'nodes'} are: ${named.slice(0, 60).join(', ')}`);
    }
    return found;
  }
  return nodes.find((o) => o.name === 'Head' || o.name === 'head')
    ?? nodes.find((o) => (o as THREE.Bone).isBone && /(^|[^a-z])head$/i.test(o.name.replace(/^mixamorig:?/i, '')))
    ?? null;
}

/** A .glb with its JSON chunk changed by `edit` (the binary chunk as it was). */
export function editGlbJson<J extends object>(glb: ArrayBuffer, edit: (json: J) => void): ArrayBuffer {
  const view = new DataView(glb);
  const jsonLength = view.getUint32(12, true);
  const json = JSON.parse(new TextDecoder().decode(new Uint8Array(glb, 20, jsonLength))) as J;
  edit(json);
  let text = new TextEncoder().encode(JSON.stringify(json));
  const padded = new Uint8Array(Math.ceil(text.length / 4) * 4).fill(0x20); // the JSON chunk is padded with spaces
  padded.set(text);
  text = padded;
  const rest = new Uint8Array(glb, 20 + jsonLength); // the BIN chunk, with its header
  const out = new Uint8Array(12 + 8 + text.length + rest.length);
  const o = new DataView(out.buffer);
  out.set(new Uint8Array(glb, 0, 12));
  o.setUint32(8, out.length, true);
  o.setUint32(12, text.length, true);
  o.setUint32(16, 0x4e4f534a, true); // 'JSON'
  out.set(text, 20);
  out.set(rest, 20 + text.length);
  return out.buffer;
}

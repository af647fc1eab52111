/**
 * Compressed glTF avatars (src/avatar/gltf-avatar.ts): meshopt compression (what gltfpack and gltf-transform's
 * optimize write) is decoded, and binds as the file it was made from; Draco meshes and required KTX2 textures,
 * which would need a decoder fetched from elsewhere, are refused with a message that says what to do instead.
 */
import { describe, expect, it } from 'vitest';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { GltfAvatar } from '../../../src/avatar/gltf-avatar';
import { ROOT } from '../helpers/exported';
import { meshopt, readGlb, writeGlb } from '../helpers/glb';

function withExtensions(name: string, used: string[], required: string[]): ArrayBuffer {
  const { json, bin } = readGlb(resolve(ROOT, 'examples/avatars', name));
  return writeGlb({ ...json, extensionsUsed: used, extensionsRequired: required }, bin);
}

describe('compressed glTF avatars', () => {
  it('decodes a meshopt-compressed avatar, which binds as the uncompressed one', async () => {
    const plain = await GltfAvatar.parse(readFileSync(resolve(ROOT, 'examples/avatars/arkit-face.glb')), 'arkit-face.glb');
    const packed = await GltfAvatar.parse(await meshopt(resolve(ROOT, 'examples/avatars/arkit-face.glb')), 'packed.glb');
    expect(packed.summary.scheme).toBe(plain.summary.scheme);
    expect(packed.summary.matched).toEqual(plain.summary.matched);
    const positions = (a: GltfAvatar) => {
      const found: number[][] = [];
      a.gltf.scene.traverse((o) => {
        const g = (o as { geometry?: { attributes: { position: { array: ArrayLike<number> } }; morphAttributes: { position?: { array: ArrayLike<number> }[] } } }).geometry;
        if (g) found.push(Array.from(g.attributes.position.array), ...(g.morphAttributes.position ?? []).map((t) => Array.from(t.array)));
      });
      return found;
    };
    expect(positions(packed)).toEqual(positions(plain)); // meshopt's vertex codec is lossless
  });

  it('refuses Draco meshes and required KTX2 textures, saying what to do instead', async () => {
    await expect(GltfAvatar.parse(withExtensions('arkit-face.glb', ['KHR_draco_mesh_compression'], ['KHR_draco_mesh_compression']), 'rpm.glb'))
      .rejects.toThrow(/^rpm\.glb is compressed with Draco \(KHR_draco_mesh_compression\), which this library does not decode: export it without mesh compression .* DRACOLoader/);
    await expect(GltfAvatar.parse(withExtensions('arkit-face.glb', ['KHR_texture_basisu'], ['KHR_texture_basisu']), 'ktx.glb'))
      .rejects.toThrow(/^ktx\.glb has KTX2 \(Basis Universal\) textures only \(KHR_texture_basisu\).* KTX2Loader/);
    // KTX2 textures beside others the loader can use instead are no obstacle.
    const optional = await GltfAvatar.parse(withExtensions('arkit-face.glb', ['KHR_texture_basisu'], []), 'ktx-optional.glb');
    expect(optional.summary.matched.length).toBe(52);
  });
});

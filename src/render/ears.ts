/**
 * Ears on the head shell (head-shell.ts), generated from the face's measures: without them the head is an egg
 * with a face on it. Each ear is a closed shell in its own frame (u forward, v up, w out from the head): an outline
 * a little wider at the top, an outer face with a rolled rim (the helix) round a darker hollow (the concha), a
 * shallow dome behind, attached along its front edge and standing out from the head by STAND_OUT. Sizes are an
 * adult's against the face's height H (chin to hairline, about 17.7 cm): about 6 cm tall, from the brow's height
 * to the nose's base, 3.3 cm wide, just behind the head's middle.
 *
 * Ears do not move with the face (they are on the skull) and read the skin's vertex colours (no shader program of
 * their own). Pure geometry apart from the colour attribute.
 */
import * as THREE from 'three';
import { SQUARENESS, type Egg, type FaceMeasures } from './head-shell';

/** How far the ear's back edge stands out from the head (radians about its front edge). */
const STAND_OUT = 0.38;
/** Rings from the ear's middle to its rim, on each face, and points round the outline. */
const RINGS = 8;
const AROUND = 28;

const smooth = (a: number, b: number, x: number) => {
  const t = Math.min(1, Math.max(0, (x - a) / (b - a)));
  return t * t * (3 - 2 * t);
};

/** Where an ear sits on a head: its middle's height and depth, its height and width (template units). */
export interface EarPlace {
  y: number;
  z: number;
  height: number;
  width: number;
}

export function earPlace(m: FaceMeasures, egg: Egg): EarPlace {
  const H = m.top - m.chin;
  return { y: m.eyeY - 0.11 * H, z: egg.center[2] - 0.09 * H, height: 0.34 * H, width: 0.19 * H };
}

/** The two ears for a head (the subject's right, at -x, first), skin-coloured (`skin`: the skin's colour). */
export function earGeometries(m: FaceMeasures, egg: Egg, skin: THREE.Color): THREE.BufferGeometry[] {
  const H = m.top - m.chin;
  const { y: cy, z: cz, height: h, width: w } = earPlace(m, egg);
  const t = 0.045 * H; // the rim's thickness
  // Where the egg's surface is at the ear's middle (its superellipsoid).
  const uy = Math.abs(cy - egg.center[1]) / (cy >= egg.center[1] ? egg.up : egg.down);
  const uz = Math.abs(cz - egg.center[2]) / (cz >= egg.center[2] ? egg.front : egg.back);
  const side = egg.ax * Math.max(0, 1 - uy ** SQUARENESS - uz ** SQUARENESS) ** (1 / SQUARENESS);
  return [-1, 1].map((s) => ear(h, w, t, skin, (u, v, out) => [egg.center[0] + s * (side - 0.15 * t + out), cy + v, cz + u], s < 0));
}

/** One ear, placed by `at(u, v, w)` (its frame to the head's); `mirrored` flips the triangles' winding. */
function ear(h: number, w: number, t: number, skin: THREE.Color, at: (u: number, v: number, w: number) => number[], mirrored: boolean): THREE.BufferGeometry {
  const positions: number[] = [], colors: number[] = [], index: number[] = [];
  const hollow = new THREE.Color().copy(skin).multiplyScalar(0.62);
  const pinker = new THREE.Color().copy(skin).lerp(new THREE.Color(0xc27a6a), 0.25).multiplyScalar(0.9);
  const c = new THREE.Color();
  // Faces: 0 the outer (rim and hollow), 1 the back; ring RINGS of both is the same outline.
  for (const face of [0, 1]) {
    for (let r = 0; r <= RINGS; r++) {
      const rho = r / RINGS;
      for (let k = 0; k < AROUND; k++) {
        const a = (2 * Math.PI * k) / AROUND;
        const v = 0.5 * h * Math.sin(a) * rho;
        const u = 0.5 * w * Math.cos(a) * rho * (1 + 0.22 * Math.sin(a)); // wider at the top, the lobe narrower
        const edge = Math.sqrt(Math.max(0, 1 - rho * rho)); // rounds the rim off to the outline
        const out = face === 0
          ? t * (0.2 + 0.8 * smooth(0.45, 0.85, rho)) * edge ** 0.35 // the hollow, then the rolled rim
          : -0.6 * t * edge; // the back, towards the head
        // Stand out about the front edge (u = w / 2): the back of the ear leaves the head.
        const lift = (0.5 * w - u) * Math.sin(STAND_OUT);
        positions.push(...at(u * Math.cos(STAND_OUT), v, out + lift));
        c.copy(pinker);
        if (face === 0) c.lerp(hollow, 1 - smooth(0.35, 0.8, rho));
        colors.push(c.r, c.g, c.b);
      }
    }
  }
  // The outline is shared by both faces (the back's own copy is left unused), so the rim's normals are smooth; each
  // face's middle is one vertex (ring 0's first).
  const id = (face: number, r: number, k: number) => ((r === RINGS ? 0 : face) * (RINGS + 1) + r) * AROUND + (r === 0 ? 0 : k % AROUND);
  for (const face of [0, 1])
    for (let r = 0; r < RINGS; r++)
      for (let k = 0; k < AROUND; k++) {
        const q = [id(face, r, k), id(face, r + 1, k), id(face, r + 1, k + 1), id(face, r, k), id(face, r + 1, k + 1), id(face, r, k + 1)];
        // The outer face looks out (+w), the back in; their outlines coincide, closing the shell.
        const tris = (face === 0) !== mirrored ? [q[0], q[2], q[1], q[3], q[5], q[4]] : q;
        for (let i = 0; i < 6; i += 3) {
          const [a, b, d] = tris.slice(i, i + 3);
          if (a !== b && b !== d && a !== d) index.push(a, b, d); // (ring 0's fan: one of each pair is empty)
        }
      }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  g.setAttribute('color', new THREE.Float32BufferAttribute(colors, 3));
  g.setIndex(index);
  g.computeVertexNormals();
  return g;
}

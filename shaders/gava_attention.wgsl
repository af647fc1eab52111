// GAVA decoder layers on the GPU (paper Eq. 1, with the augmented adjacency), batched over frames.
// One workgroup per token per frame: workgroup_id = (token, frame), one invocation per channel.
// Tokens 0..N-1 are vertices (they attend to themselves and their 1-ring, from CSR lists);
// token N is the pose token (it attends to every token). Same maths as src/attention/reference.ts.

override D: u32;        // d_model; also the workgroup size (a power of two, for the reductions)
override HEADS: u32;
override FFN: u32;     // feed-forward width, at most MAX_FFN
override LN_EPS: f32;  // LayerNorm epsilon
// (every override comes from models/manifest.json: model.config and model.layer_norm_eps; none has a default)
const MAX_FFN: u32 = 512u;
const MAX_D: u32 = 256u;

struct Params {
  n: u32,            // vertices
  t: u32,            // tokens = n + 1
  frames: u32,
  layer_base: u32,   // offset of this layer's weights in `weights`
  final_base: u32,   // offset of the final LayerNorm and heads
  max_rotation: f32,
  max_translation: f32,
  _pad: u32,
}

@group(0) @binding(0) var<storage, read_write> x: array<f32>;        // (frames, t, D) residual stream
@group(0) @binding(1) var<storage, read_write> qkv: array<f32>;      // (frames, t, 3D)
@group(0) @binding(2) var<storage, read_write> attn: array<f32>;     // (frames, t, D) attention output; first the latents
@group(0) @binding(3) var<uniform> params: Params;
@group(0) @binding(4) var<storage, read> csr_offsets: array<u32>;    // (n + 1) 1-ring row starts
@group(0) @binding(5) var<storage, read> csr_indices: array<u32>;    // 1-ring neighbours (no self)
@group(0) @binding(6) var<storage, read> weights: array<f32>;        // all layers, the heads, then the vertex tokens' e and W
@group(0) @binding(7) var<storage, read_write> result: array<f32>;   // (frames, n, 3) offsets, then (frames, 6) pose

var<workgroup> red: array<f32, MAX_D>;
var<workgroup> hbuf: array<f32, MAX_D>;
var<workgroup> hidden: array<f32, MAX_FFN>;

// Offsets inside one layer's packed weights (the order of decoderWeights / packWeights in gpu-decoder.ts).
fn o_ln1g() -> u32 { return 0u; }
fn o_ln1b() -> u32 { return D; }
fn o_qkvw() -> u32 { return 2u * D; }
fn o_qkvb() -> u32 { return 2u * D + 3u * D * D; }
fn o_outw() -> u32 { return o_qkvb() + 3u * D; }
fn o_outb() -> u32 { return o_outw() + D * D; }
fn o_ln2g() -> u32 { return o_outb() + D; }
fn o_ln2b() -> u32 { return o_ln2g() + D; }
fn o_ffn1w() -> u32 { return o_ln2b() + D; }
fn o_ffn1b() -> u32 { return o_ffn1w() + FFN * D; }
fn o_ffn2w() -> u32 { return o_ffn1b() + FFN; }
fn o_ffn2b() -> u32 { return o_ffn2w() + D * FFN; }

// Sum of `v` over the workgroup (every invocation gets the total).
fn workgroup_sum(i: u32, v: f32) -> f32 {
  red[i] = v;
  workgroupBarrier();
  var stride = D / 2u;
  loop {
    if (stride == 0u) { break; }
    if (i < stride) { red[i] = red[i] + red[i + stride]; }
    workgroupBarrier();
    stride = stride / 2u;
  }
  let total = red[0];
  workgroupBarrier();
  return total;
}

// LayerNorm of one token (value xi held by invocation i) into hbuf.
fn layer_norm(i: u32, xi: f32, g: u32, b: u32) {
  let mean = workgroup_sum(i, xi) / f32(D);
  let dev = xi - mean;
  let variance = workgroup_sum(i, dev * dev) / f32(D);
  hbuf[i] = dev * inverseSqrt(variance + LN_EPS) * weights[g + i] + weights[b + i];
  workgroupBarrier();
}

// erf by Abramowitz & Stegun 7.1.26, as in reference.ts.
fn erf(v: f32) -> f32 {
  let a = abs(v);
  let t = 1.0 / (1.0 + 0.3275911 * a);
  let y = 1.0 - ((((1.061405429 * t - 1.453152027) * t + 1.421413741) * t - 0.284496736) * t + 0.254829592) * t * exp(-a * a);
  return sign(v) * y;
}

fn gelu(v: f32) -> f32 { return 0.5 * v * (1.0 + erf(v * 0.70710678118654752)); }

// The vertex tokens of the hierarchical latents, before the first layer: attn holds each frame's [a, g] (2D numbers,
// from hierarchical.onnx), and vertex j's token is local_out(gelu(a + e_j)) + g (reference.ts vertexTokens). The
// weights after the heads' (11 D + 9 numbers) are e (n, D), local_out's W (D, D) and b (D). The pose token's row of
// x is the one the CPU wrote.
@compute @workgroup_size(D)
fn vertex_tokens(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
  let i = lid.x;
  let j = wid.x;
  let frame = wid.y;
  if (j >= params.n) { return; }
  let e = params.final_base + 11u * D + 9u;
  let w = e + params.n * D;
  let latents = frame * 2u * D;
  hbuf[i] = gelu(attn[latents + i] + weights[e + j * D + i]);
  workgroupBarrier();
  var acc = weights[w + D * D + i];
  for (var k = 0u; k < D; k = k + 1u) { acc = acc + weights[w + i * D + k] * hbuf[k]; }
  x[(frame * params.t + j) * D + i] = acc + attn[latents + D + i];
}

@compute @workgroup_size(D)
fn ln_qkv(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
  let i = lid.x;
  let token = (wid.y * params.t + wid.x);
  let lb = params.layer_base;
  layer_norm(i, x[token * D + i], lb + o_ln1g(), lb + o_ln1b());
  for (var r = 0u; r < 3u; r = r + 1u) {
    let row = r * D + i;
    var acc = weights[lb + o_qkvb() + row];
    let w = lb + o_qkvw() + row * D;
    for (var k = 0u; k < D; k = k + 1u) { acc = acc + weights[w + k] * hbuf[k]; }
    qkv[token * 3u * D + row] = acc;
  }
}

@compute @workgroup_size(D)
fn attend(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
  let i = lid.x;
  let tok = wid.x;
  let frame_base = wid.y * params.t;
  let dk = D / HEADS;
  let head = i / dk;
  let q = (frame_base + tok) * 3u * D + head * dk;
  let scale = inverseSqrt(f32(dk));
  var count = params.t;          // the pose token sees every token
  var row = 0u;
  if (tok < params.n) {
    row = csr_offsets[tok];
    count = 1u + csr_offsets[tok + 1u] - row;
  }
  // Online softmax (one pass, running max), so any number of keys fits without workgroup memory.
  var m = -3.0e38;
  var l = 0.0;
  var acc = 0.0;
  for (var s = 0u; s < count; s = s + 1u) {
    var key = s;
    if (tok < params.n) {
      key = tok;
      if (s > 0u) { key = csr_indices[row + s - 1u]; }
    }
    let kb = (frame_base + key) * 3u * D;
    var dot = 0.0;
    for (var j = 0u; j < dk; j = j + 1u) { dot = dot + qkv[q + j] * qkv[kb + D + head * dk + j]; }
    let score = dot * scale;
    let m_new = max(m, score);
    let correction = exp(m - m_new);
    let p = exp(score - m_new);
    l = l * correction + p;
    acc = acc * correction + p * qkv[kb + 2u * D + i];
    m = m_new;
  }
  attn[(frame_base + tok) * D + i] = acc / l;
}

@compute @workgroup_size(D)
fn out_ffn(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
  let i = lid.x;
  let token = wid.y * params.t + wid.x;
  let lb = params.layer_base;
  var a = weights[lb + o_outb() + i];
  for (var k = 0u; k < D; k = k + 1u) { a = a + weights[lb + o_outw() + i * D + k] * attn[token * D + k]; }
  let xi = x[token * D + i] + a;
  layer_norm(i, xi, lb + o_ln2g(), lb + o_ln2b());
  for (var r = i; r < FFN; r = r + D) {
    var v = weights[lb + o_ffn1b() + r];
    for (var k = 0u; k < D; k = k + 1u) { v = v + weights[lb + o_ffn1w() + r * D + k] * hbuf[k]; }
    hidden[r] = gelu(v);
  }
  workgroupBarrier();
  var y = weights[lb + o_ffn2b() + i];
  for (var r = 0u; r < FFN; r = r + 1u) { y = y + weights[lb + o_ffn2w() + i * FFN + r] * hidden[r]; }
  x[token * D + i] = xi + y;
}

@compute @workgroup_size(D)
fn heads(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
  let i = lid.x;
  let tok = wid.x;
  let frame = wid.y;
  let token = frame * params.t + tok;
  let fb = params.final_base;
  layer_norm(i, x[token * D + i], fb, fb + D);
  let disp_w = fb + 2u * D;
  let disp_b = disp_w + 3u * D;
  let pose_w = disp_b + 3u;
  let pose_b = pose_w + 6u * D;
  if (tok < params.n && i < 3u) {
    var v = weights[disp_b + i];
    for (var k = 0u; k < D; k = k + 1u) { v = v + weights[disp_w + i * D + k] * hbuf[k]; }
    result[(frame * params.n + tok) * 3u + i] = v;
  }
  if (tok == params.n && i < 6u) {
    var v = weights[pose_b + i];
    for (var k = 0u; k < D; k = k + 1u) { v = v + weights[pose_w + i * D + k] * hbuf[k]; }
    var bound = params.max_translation;
    if (i < 3u) { bound = params.max_rotation; }
    // tanh is undefined past |x| = 88.7 in WGSL (NaN on some GPUs); at 15 it is 1 in f32, as Math.tanh saturates.
    result[params.frames * params.n * 3u + frame * 6u + i] = bound * tanh(clamp(v, -15.0, 15.0));
  }
}

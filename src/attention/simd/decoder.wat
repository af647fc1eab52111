;; The CPU decoder's layers in WebAssembly SIMD (four float lanes): matrix products, attention,
;; LayerNorm, GELU and residual sums. LayerNorm and GELU also in float64 exactly as the TypeScript
;; kernel computes them (layer_norm_f64, gelu_table), used where the sizes are not multiples of 4.
;;
;; Assembled by `npm run build:wasm` (scripts/build-wasm.ts) into decoder-wasm.ts, which embeds the
;; bytes; a unit test assembles this file again and checks the embedded bytes are what it gives.
;; decoder-kernels.ts (SimdKernel) drives it; its TypeScript twin is jsKernel in the same file.
;;
;; All pointers are byte addresses in the exported memory, all values float32.
(module
  (memory (export "memory") 1)

  ;; out[t, o] = b[o] + sum_i wt[i, o] * x[t, i]   for t < rows, o < outs
  ;; wt: cols x outs (the weight matrix transposed, so four consecutive outputs are one vector load),
  ;; x: rows x cols, out: rows x outs, row-major. Needs rows even (callers pad the token count) and
  ;; outs a multiple of 4. Two tokens at a time share every weight load; outputs go 16 at a time
  ;; (eight accumulators), then 4 at a time for what is left.
  (func (export "matmul")
    (param $wt i32) (param $b i32) (param $outs i32) (param $cols i32)
    (param $x i32) (param $rows i32) (param $out i32)
    (local $t i32) (local $o i32) (local $i i32) (local $stride i32) (local $xrow i32)
    (local $xp0 i32) (local $xp1 i32) (local $wp i32) (local $op0 i32) (local $op1 i32)
    (local $p v128) (local $q v128) (local $w v128)
    (local $a0 v128) (local $a1 v128) (local $a2 v128) (local $a3 v128)
    (local $c0 v128) (local $c1 v128) (local $c2 v128) (local $c3 v128)
    (local.set $stride (i32.shl (local.get $outs) (i32.const 2)))
    (local.set $xrow (i32.shl (local.get $cols) (i32.const 2)))
    (local.set $t (i32.const 0))
    (block $rows_done
      (loop $rows_loop
        (br_if $rows_done (i32.ge_u (local.get $t) (local.get $rows)))
        (local.set $xp0 (i32.add (local.get $x) (i32.mul (local.get $t) (local.get $xrow))))
        (local.set $xp1 (i32.add (local.get $xp0) (local.get $xrow)))
        (local.set $op0 (i32.add (local.get $out) (i32.mul (local.get $t) (local.get $stride))))
        (local.set $op1 (i32.add (local.get $op0) (local.get $stride)))
        (local.set $o (i32.const 0))
        ;; sixteen outputs at a time
        (block $wide_done
          (loop $wide_loop
            (br_if $wide_done (i32.gt_u (i32.add (local.get $o) (i32.const 16)) (local.get $outs)))
            (local.set $wp (i32.add (local.get $b) (i32.shl (local.get $o) (i32.const 2))))
            (local.set $a0 (v128.load offset=0 (local.get $wp)))
            (local.set $a1 (v128.load offset=16 (local.get $wp)))
            (local.set $a2 (v128.load offset=32 (local.get $wp)))
            (local.set $a3 (v128.load offset=48 (local.get $wp)))
            (local.set $c0 (local.get $a0))
            (local.set $c1 (local.get $a1))
            (local.set $c2 (local.get $a2))
            (local.set $c3 (local.get $a3))
            (local.set $wp (i32.add (local.get $wt) (i32.shl (local.get $o) (i32.const 2))))
            (local.set $i (i32.const 0))
            (loop $k_loop
              (local.set $p (v128.load32_splat (i32.add (local.get $xp0) (local.get $i))))
              (local.set $q (v128.load32_splat (i32.add (local.get $xp1) (local.get $i))))
              (local.set $w (v128.load offset=0 (local.get $wp)))
              (local.set $a0 (f32x4.add (local.get $a0) (f32x4.mul (local.get $w) (local.get $p))))
              (local.set $c0 (f32x4.add (local.get $c0) (f32x4.mul (local.get $w) (local.get $q))))
              (local.set $w (v128.load offset=16 (local.get $wp)))
              (local.set $a1 (f32x4.add (local.get $a1) (f32x4.mul (local.get $w) (local.get $p))))
              (local.set $c1 (f32x4.add (local.get $c1) (f32x4.mul (local.get $w) (local.get $q))))
              (local.set $w (v128.load offset=32 (local.get $wp)))
              (local.set $a2 (f32x4.add (local.get $a2) (f32x4.mul (local.get $w) (local.get $p))))
              (local.set $c2 (f32x4.add (local.get $c2) (f32x4.mul (local.get $w) (local.get $q))))
              (local.set $w (v128.load offset=48 (local.get $wp)))
              (local.set $a3 (f32x4.add (local.get $a3) (f32x4.mul (local.get $w) (local.get $p))))
              (local.set $c3 (f32x4.add (local.get $c3) (f32x4.mul (local.get $w) (local.get $q))))
              (local.set $wp (i32.add (local.get $wp) (local.get $stride)))
              (local.set $i (i32.add (local.get $i) (i32.const 4)))
              (br_if $k_loop (i32.lt_u (local.get $i) (local.get $xrow))))
            (local.set $wp (i32.add (local.get $op0) (i32.shl (local.get $o) (i32.const 2))))
            (v128.store offset=0 (local.get $wp) (local.get $a0))
            (v128.store offset=16 (local.get $wp) (local.get $a1))
            (v128.store offset=32 (local.get $wp) (local.get $a2))
            (v128.store offset=48 (local.get $wp) (local.get $a3))
            (local.set $wp (i32.add (local.get $op1) (i32.shl (local.get $o) (i32.const 2))))
            (v128.store offset=0 (local.get $wp) (local.get $c0))
            (v128.store offset=16 (local.get $wp) (local.get $c1))
            (v128.store offset=32 (local.get $wp) (local.get $c2))
            (v128.store offset=48 (local.get $wp) (local.get $c3))
            (local.set $o (i32.add (local.get $o) (i32.const 16)))
            (br $wide_loop)))
        ;; four outputs at a time
        (block $narrow_done
          (loop $narrow_loop
            (br_if $narrow_done (i32.ge_u (local.get $o) (local.get $outs)))
            (local.set $a0 (v128.load (i32.add (local.get $b) (i32.shl (local.get $o) (i32.const 2)))))
            (local.set $c0 (local.get $a0))
            (local.set $wp (i32.add (local.get $wt) (i32.shl (local.get $o) (i32.const 2))))
            (local.set $i (i32.const 0))
            (loop $k_loop4
              (local.set $w (v128.load (local.get $wp)))
              (local.set $a0 (f32x4.add (local.get $a0)
                (f32x4.mul (local.get $w) (v128.load32_splat (i32.add (local.get $xp0) (local.get $i))))))
              (local.set $c0 (f32x4.add (local.get $c0)
                (f32x4.mul (local.get $w) (v128.load32_splat (i32.add (local.get $xp1) (local.get $i))))))
              (local.set $wp (i32.add (local.get $wp) (local.get $stride)))
              (local.set $i (i32.add (local.get $i) (i32.const 4)))
              (br_if $k_loop4 (i32.lt_u (local.get $i) (local.get $xrow))))
            (v128.store (i32.add (local.get $op0) (i32.shl (local.get $o) (i32.const 2))) (local.get $a0))
            (v128.store (i32.add (local.get $op1) (i32.shl (local.get $o) (i32.const 2))) (local.get $c0))
            (local.set $o (i32.add (local.get $o) (i32.const 4)))
            (br $narrow_loop)))
        (local.set $t (i32.add (local.get $t) (i32.const 2)))
        (br $rows_loop))))
;; x[i] += y[i] for i < count
  (func (export "add") (param $x i32) (param $y i32) (param $count i32)
    (local $end i32) (local $end4 i32)
    (local.set $end (i32.add (local.get $x) (i32.shl (local.get $count) (i32.const 2))))
    (local.set $end4 (i32.add (local.get $x) (i32.shl (i32.and (local.get $count) (i32.const -4)) (i32.const 2))))
    (block $done
      (loop $vec
        (br_if $done (i32.ge_u (local.get $x) (local.get $end4)))
        (v128.store (local.get $x) (f32x4.add (v128.load (local.get $x)) (v128.load (local.get $y))))
        (local.set $x (i32.add (local.get $x) (i32.const 16)))
        (local.set $y (i32.add (local.get $y) (i32.const 16)))
        (br $vec)))
    (block $done1
      (loop $one
        (br_if $done1 (i32.ge_u (local.get $x) (local.get $end)))
        (f32.store (local.get $x) (f32.add (f32.load (local.get $x)) (f32.load (local.get $y))))
        (local.set $x (i32.add (local.get $x) (i32.const 4)))
        (local.set $y (i32.add (local.get $y) (i32.const 4)))
        (br $one))))

  ;; out[r, i] = x[r, i] + row[i] for r < rows, i < d: one row added to every row of x (d a multiple of 4)
  (func (export "add_row") (param $x i32) (param $row i32) (param $rows i32) (param $d i32) (param $out i32)
    (local $end i32) (local $bytes i32) (local $i i32)
    (local.set $bytes (i32.shl (local.get $d) (i32.const 2)))
    (local.set $end (i32.add (local.get $x) (i32.mul (local.get $rows) (local.get $bytes))))
    (block $done
      (loop $rows_loop
        (br_if $done (i32.ge_u (local.get $x) (local.get $end)))
        (local.set $i (i32.const 0))
        (block $row_done
          (loop $cols
            (br_if $row_done (i32.ge_u (local.get $i) (local.get $bytes)))
            (v128.store (i32.add (local.get $out) (local.get $i))
              (f32x4.add (v128.load (i32.add (local.get $x) (local.get $i))) (v128.load (i32.add (local.get $row) (local.get $i)))))
            (local.set $i (i32.add (local.get $i) (i32.const 16)))
            (br $cols)))
        (local.set $x (i32.add (local.get $x) (local.get $bytes)))
        (local.set $out (i32.add (local.get $out) (local.get $bytes)))
        (br $rows_loop))))

  ;; Row-wise LayerNorm of x (rows x d) into out, in float64 (mean, variance, eps as given), any d
  (func $layer_norm_f64 (param $x i32) (param $rows i32) (param $d i32) (param $g i32) (param $b i32) (param $out i32) (param $eps f64)
    (local $t i32) (local $i i32) (local $row i32) (local $mean f64) (local $var f64) (local $c f64) (local $inv f64)
    (local $db i32)
    (local.set $db (i32.shl (local.get $d) (i32.const 2)))
    (block $rows_done
      (loop $rows_loop
        (br_if $rows_done (i32.ge_u (local.get $t) (local.get $rows)))
        (local.set $row (i32.mul (local.get $t) (local.get $db)))
        (local.set $mean (f64.const 0))
        (local.set $i (i32.const 0))
        (loop $sum
          (local.set $mean (f64.add (local.get $mean)
            (f64.promote_f32 (f32.load (i32.add (local.get $x) (i32.add (local.get $row) (local.get $i)))))))
          (local.set $i (i32.add (local.get $i) (i32.const 4)))
          (br_if $sum (i32.lt_u (local.get $i) (local.get $db))))
        (local.set $mean (f64.div (local.get $mean) (f64.convert_i32_u (local.get $d))))
        (local.set $var (f64.const 0))
        (local.set $i (i32.const 0))
        (loop $sq
          (local.set $c (f64.sub
            (f64.promote_f32 (f32.load (i32.add (local.get $x) (i32.add (local.get $row) (local.get $i)))))
            (local.get $mean)))
          (local.set $var (f64.add (local.get $var) (f64.mul (local.get $c) (local.get $c))))
          (local.set $i (i32.add (local.get $i) (i32.const 4)))
          (br_if $sq (i32.lt_u (local.get $i) (local.get $db))))
        (local.set $inv (f64.div (f64.const 1)
          (f64.sqrt (f64.add (f64.div (local.get $var) (f64.convert_i32_u (local.get $d))) (local.get $eps)))))
        (local.set $i (i32.const 0))
        (loop $norm
          (f32.store (i32.add (local.get $out) (i32.add (local.get $row) (local.get $i)))
            (f32.demote_f64 (f64.add
              (f64.mul
                (f64.mul
                  (f64.sub (f64.promote_f32 (f32.load (i32.add (local.get $x) (i32.add (local.get $row) (local.get $i)))))
                           (local.get $mean))
                  (local.get $inv))
                (f64.promote_f32 (f32.load (i32.add (local.get $g) (local.get $i)))))
              (f64.promote_f32 (f32.load (i32.add (local.get $b) (local.get $i)))))))
          (local.set $i (i32.add (local.get $i) (i32.const 4)))
          (br_if $norm (i32.lt_u (local.get $i) (local.get $db))))
        (local.set $t (i32.add (local.get $t) (i32.const 1)))
        (br $rows_loop))))

  ;; GELU in place over a[0..count): the exact function tabulated (value, slope: float64, `steps` points
  ;; per unit on [-range, range]) with cubic Hermite interpolation, as decoder-kernels.ts's geluInPlace.
  (func $gelu_table (param $a i32) (param $count i32) (param $value i32) (param $slope i32) (param $range f64) (param $steps f64)
    (local $end i32) (local $x f64) (local $u f64) (local $k f64) (local $s f64) (local $s2 f64) (local $s3 f64) (local $o i32)
    (local.set $end (i32.add (local.get $a) (i32.shl (local.get $count) (i32.const 2))))
    (block $done
      (loop $each
        (br_if $done (i32.ge_u (local.get $a) (local.get $end)))
        (local.set $x (f64.promote_f32 (f32.load (local.get $a))))
        (if (f64.lt (local.get $x) (local.get $range))
          (then
            (if (f64.le (local.get $x) (f64.neg (local.get $range)))
              (then (f32.store (local.get $a) (f32.const 0)))
              (else
                (local.set $u (f64.mul (f64.add (local.get $x) (local.get $range)) (local.get $steps)))
                (local.set $k (f64.floor (local.get $u)))
                (local.set $s (f64.sub (local.get $u) (local.get $k)))
                (local.set $s2 (f64.mul (local.get $s) (local.get $s)))
                (local.set $s3 (f64.mul (local.get $s2) (local.get $s)))
                (local.set $o (i32.shl (i32.trunc_f64_s (local.get $k)) (i32.const 3)))
                (f32.store (local.get $a) (f32.demote_f64
                  (f64.add
                    (f64.add
                      (f64.add
                        (f64.mul
                          (f64.add (f64.sub (f64.mul (f64.const 2) (local.get $s3)) (f64.mul (f64.const 3) (local.get $s2))) (f64.const 1))
                          (f64.load (i32.add (local.get $value) (local.get $o))))
                        (f64.mul
                          (f64.add (f64.sub (local.get $s3) (f64.mul (f64.const 2) (local.get $s2))) (local.get $s))
                          (f64.load (i32.add (local.get $slope) (local.get $o)))))
                      (f64.mul
                        (f64.sub (f64.mul (f64.const 3) (local.get $s2)) (f64.mul (f64.const 2) (local.get $s3)))
                        (f64.load offset=8 (i32.add (local.get $value) (local.get $o)))))
                    (f64.mul
                      (f64.sub (local.get $s3) (local.get $s2))
                      (f64.load offset=8 (i32.add (local.get $slope) (local.get $o)))))))))))
        (local.set $a (i32.add (local.get $a) (i32.const 4)))
        (br $each))))


  ;; Neighbour-masked multi-head attention over `tokens` tokens: qkv rows (tokens x 3d: queries, keys,
  ;; values), token t attends to keys key_index[key_start[t] .. key_start[t + 1]) (int32), softmax of
  ;; q.k * scale per head, weights times values into out (tokens x d). `scores`: float32 scratch for the
  ;; longest key list plus 3, 16-byte aligned. Head size d / heads must be a multiple of 4. The softmax's
  ;; exponentials go four keys at a time ($exp4; the lanes past the list are -87, weight ~1e-38).
  (func (export "attention")
    (param $qkv i32) (param $tokens i32) (param $d i32) (param $heads i32)
    (param $key_start i32) (param $key_index i32) (param $scores i32) (param $out i32) (param $scale f32)
    (local $t i32) (local $hd i32) (local $s i32) (local $k0 i32) (local $k1 i32) (local $i i32)
    (local $row3 i32) (local $db i32) (local $dkb i32) (local $qo i32) (local $ko i32) (local $ao i32) (local $sp i32)
    (local $acc v128) (local $w v128) (local $dot f32) (local $max f32) (local $inv f32) (local $m v128) (local $end i32)
    (local.set $db (i32.shl (local.get $d) (i32.const 2)))
    (local.set $row3 (i32.mul (local.get $db) (i32.const 3)))
    (local.set $dkb (i32.div_u (local.get $db) (local.get $heads)))
    (block $tokens_done
      (loop $tokens_loop
        (br_if $tokens_done (i32.ge_u (local.get $t) (local.get $tokens)))
        (local.set $k0 (i32.load (i32.add (local.get $key_start) (i32.shl (local.get $t) (i32.const 2)))))
        (local.set $k1 (i32.load offset=4 (i32.add (local.get $key_start) (i32.shl (local.get $t) (i32.const 2)))))
        (local.set $hd (i32.const 0))
        (loop $heads_loop
          (local.set $qo (i32.add (local.get $qkv)
            (i32.add (i32.mul (local.get $t) (local.get $row3)) (i32.mul (local.get $hd) (local.get $dkb)))))
          ;; scores and their maximum
          (local.set $max (f32.const -inf))
          (local.set $s (local.get $k0))
          (local.set $sp (local.get $scores))
          (block $scored
            (loop $score_loop
              (br_if $scored (i32.ge_u (local.get $s) (local.get $k1)))
              (local.set $ko (i32.add (local.get $qkv)
                (i32.add (i32.add (i32.mul (i32.load (i32.add (local.get $key_index) (i32.shl (local.get $s) (i32.const 2))))
                                           (local.get $row3))
                                  (local.get $db))
                         (i32.mul (local.get $hd) (local.get $dkb)))))
              (local.set $acc (f32x4.mul (v128.load (local.get $qo)) (v128.load (local.get $ko))))
              (local.set $i (i32.const 16))
              (block $dot_done
                (loop $dot_loop
                  (br_if $dot_done (i32.ge_u (local.get $i) (local.get $dkb)))
                  (local.set $acc (f32x4.add (local.get $acc)
                    (f32x4.mul (v128.load (i32.add (local.get $qo) (local.get $i))) (v128.load (i32.add (local.get $ko) (local.get $i))))))
                  (local.set $i (i32.add (local.get $i) (i32.const 16)))
                  (br $dot_loop)))
              (local.set $dot (f32.mul (local.get $scale)
                (f32.add (f32.add (f32x4.extract_lane 0 (local.get $acc)) (f32x4.extract_lane 1 (local.get $acc)))
                         (f32.add (f32x4.extract_lane 2 (local.get $acc)) (f32x4.extract_lane 3 (local.get $acc))))))
              (f32.store (local.get $sp) (local.get $dot))
              (local.set $max (f32.max (local.get $max) (local.get $dot)))
              (local.set $sp (i32.add (local.get $sp) (i32.const 4)))
              (local.set $s (i32.add (local.get $s) (i32.const 1)))
              (br $score_loop)))
          ;; softmax, four keys at a time: pad the list to a multiple of 4 with scores that vanish
          (f32.store offset=0 (local.get $sp) (f32.const -1e30))
          (f32.store offset=4 (local.get $sp) (f32.const -1e30))
          (f32.store offset=8 (local.get $sp) (f32.const -1e30))
          (local.set $end (i32.add (local.get $scores) (i32.shl (i32.sub (local.get $k1) (local.get $k0)) (i32.const 2))))
          (local.set $m (f32x4.splat (local.get $max)))
          (local.set $acc (v128.const f32x4 0 0 0 0))
          (local.set $sp (local.get $scores))
          (loop $exp_loop
            (local.set $w (call $exp4 (f32x4.max (f32x4.sub (v128.load (local.get $sp)) (local.get $m))
                                                 (v128.const f32x4 -87 -87 -87 -87))))
            (v128.store (local.get $sp) (local.get $w))
            (local.set $acc (f32x4.add (local.get $acc) (local.get $w)))
            (local.set $sp (i32.add (local.get $sp) (i32.const 16)))
            (br_if $exp_loop (i32.lt_u (local.get $sp) (local.get $end))))
          (local.set $inv (f32.div (f32.const 1)
            (f32.add (f32.add (f32x4.extract_lane 0 (local.get $acc)) (f32x4.extract_lane 1 (local.get $acc)))
                     (f32.add (f32x4.extract_lane 2 (local.get $acc)) (f32x4.extract_lane 3 (local.get $acc))))))
          ;; weighted sum of the values
          (local.set $ao (i32.add (local.get $out)
            (i32.add (i32.mul (local.get $t) (local.get $db)) (i32.mul (local.get $hd) (local.get $dkb)))))
          (local.set $i (i32.const 0))
          (loop $zero
            (v128.store (i32.add (local.get $ao) (local.get $i)) (v128.const f32x4 0 0 0 0))
            (local.set $i (i32.add (local.get $i) (i32.const 16)))
            (br_if $zero (i32.lt_u (local.get $i) (local.get $dkb))))
          (local.set $sp (local.get $scores))
          (local.set $s (local.get $k0))
          (block $summed
            (loop $value_loop
              (br_if $summed (i32.ge_u (local.get $s) (local.get $k1)))
              (local.set $w (f32x4.splat (f32.mul (f32.load (local.get $sp)) (local.get $inv))))
              (local.set $ko (i32.add (local.get $qkv)
                (i32.add (i32.add (i32.mul (i32.load (i32.add (local.get $key_index) (i32.shl (local.get $s) (i32.const 2))))
                                           (local.get $row3))
                                  (i32.shl (local.get $db) (i32.const 1)))
                         (i32.mul (local.get $hd) (local.get $dkb)))))
              (local.set $i (i32.const 0))
              (loop $acc_loop
                (v128.store (i32.add (local.get $ao) (local.get $i))
                  (f32x4.add (v128.load (i32.add (local.get $ao) (local.get $i)))
                             (f32x4.mul (local.get $w) (v128.load (i32.add (local.get $ko) (local.get $i))))))
                (local.set $i (i32.add (local.get $i) (i32.const 16)))
                (br_if $acc_loop (i32.lt_u (local.get $i) (local.get $dkb))))
              (local.set $sp (i32.add (local.get $sp) (i32.const 4)))
              (local.set $s (i32.add (local.get $s) (i32.const 1)))
              (br $value_loop)))
          (local.set $hd (i32.add (local.get $hd) (i32.const 1)))
          (br_if $heads_loop (i32.lt_u (local.get $hd) (local.get $heads))))
        (local.set $t (i32.add (local.get $t) (i32.const 1)))
        (br $tokens_loop))))

  ;; The same attention for the model's shape, d = 32 in 4 heads of 8 (SimdKernel picks it): the four heads
  ;; of a key together, so a key's row is found once, not once per head, and its four scores are one vector
  ;; (lane h: head h). The softmax then goes four heads at a time and the weighted sum of the values stays in
  ;; registers. The same operations as attention above, in the same order, but for the softmax's denominator
  ;; (summed key after key here, four keys to a lane there); in the fused module (decoder-fma-wasm.ts) each
  ;; multiply-add is one rounding, so its sums differ in the last bits. `scores`: 16 bytes per key of the longest list,
  ;; 16-byte aligned. qkv rows are 384 bytes: the query at 0, the key at 128, the value at 256; out rows 128 bytes.
  (func (export "attention_d32h4")
    (param $qkv i32) (param $tokens i32) (param $key_start i32) (param $key_index i32) (param $scores i32)
    (param $out i32) (param $scale f32)
    (local $t i32) (local $s i32) (local $k0 i32) (local $k1 i32) (local $q i32) (local $kp i32) (local $sp i32)
    (local $end i32) (local $op i32)
    (local $q0 v128) (local $q1 v128) (local $q2 v128) (local $q3 v128) (local $q4 v128) (local $q5 v128) (local $q6 v128) (local $q7 v128)
    (local $a0 v128) (local $a1 v128) (local $a2 v128) (local $a3 v128)
    (local $m v128) (local $p v128) (local $w v128) (local $inv v128) (local $ex v128) (local $ek v128) (local $er v128)
    (local $o0 v128) (local $o1 v128) (local $o2 v128) (local $o3 v128) (local $o4 v128) (local $o5 v128) (local $o6 v128) (local $o7 v128)
    (block $tokens_done
      (loop $tokens_loop
        (br_if $tokens_done (i32.ge_u (local.get $t) (local.get $tokens)))
        (local.set $k0 (i32.load (i32.add (local.get $key_start) (i32.shl (local.get $t) (i32.const 2)))))
        (local.set $k1 (i32.load offset=4 (i32.add (local.get $key_start) (i32.shl (local.get $t) (i32.const 2)))))
        (local.set $q (i32.add (local.get $qkv) (i32.mul (local.get $t) (i32.const 384))))
        (local.set $q0 (v128.load offset=0 (local.get $q)))
        (local.set $q1 (v128.load offset=16 (local.get $q)))
        (local.set $q2 (v128.load offset=32 (local.get $q)))
        (local.set $q3 (v128.load offset=48 (local.get $q)))
        (local.set $q4 (v128.load offset=64 (local.get $q)))
        (local.set $q5 (v128.load offset=80 (local.get $q)))
        (local.set $q6 (v128.load offset=96 (local.get $q)))
        (local.set $q7 (v128.load offset=112 (local.get $q)))
        ;; scores, a vector per key, and their maximum per head
        (local.set $m (v128.const f32x4 -inf -inf -inf -inf))
        (local.set $sp (local.get $scores))
        (local.set $s (local.get $k0))
        (block $scored
          (loop $score_loop
            (br_if $scored (i32.ge_u (local.get $s) (local.get $k1)))
            (local.set $kp (i32.add (local.get $qkv)
              (i32.mul (i32.load (i32.add (local.get $key_index) (i32.shl (local.get $s) (i32.const 2)))) (i32.const 384))))
            (local.set $a0 (f32x4.add (f32x4.mul (local.get $q0) (v128.load offset=128 (local.get $kp)))
                                      (f32x4.mul (local.get $q1) (v128.load offset=144 (local.get $kp)))))
            (local.set $a1 (f32x4.add (f32x4.mul (local.get $q2) (v128.load offset=160 (local.get $kp)))
                                      (f32x4.mul (local.get $q3) (v128.load offset=176 (local.get $kp)))))
            (local.set $a2 (f32x4.add (f32x4.mul (local.get $q4) (v128.load offset=192 (local.get $kp)))
                                      (f32x4.mul (local.get $q5) (v128.load offset=208 (local.get $kp)))))
            (local.set $a3 (f32x4.add (f32x4.mul (local.get $q6) (v128.load offset=224 (local.get $kp)))
                                      (f32x4.mul (local.get $q7) (v128.load offset=240 (local.get $kp)))))
            ;; lane h of the result: the sum of a_h's four lanes, (0 + 1) + (2 + 3) as attention sums them (plain module)
            (local.set $a0 (f32x4.add (i8x16.shuffle 0 1 2 3 16 17 18 19 8 9 10 11 24 25 26 27 (local.get $a0) (local.get $a1))
                                      (i8x16.shuffle 4 5 6 7 20 21 22 23 12 13 14 15 28 29 30 31 (local.get $a0) (local.get $a1))))
            (local.set $a2 (f32x4.add (i8x16.shuffle 0 1 2 3 16 17 18 19 8 9 10 11 24 25 26 27 (local.get $a2) (local.get $a3))
                                      (i8x16.shuffle 4 5 6 7 20 21 22 23 12 13 14 15 28 29 30 31 (local.get $a2) (local.get $a3))))
            (local.set $p (f32x4.mul (f32x4.splat (local.get $scale))
              (f32x4.add (i8x16.shuffle 0 1 2 3 4 5 6 7 16 17 18 19 20 21 22 23 (local.get $a0) (local.get $a2))
                         (i8x16.shuffle 8 9 10 11 12 13 14 15 24 25 26 27 28 29 30 31 (local.get $a0) (local.get $a2)))))
            (v128.store (local.get $sp) (local.get $p))
            (local.set $m (f32x4.max (local.get $m) (local.get $p)))
            (local.set $sp (i32.add (local.get $sp) (i32.const 16)))
            (local.set $s (i32.add (local.get $s) (i32.const 1)))
            (br $score_loop)))
        ;; softmax per head (every token has a key: itself)
        (local.set $end (local.get $sp))
        (local.set $inv (v128.const f32x4 0 0 0 0))
        (local.set $sp (local.get $scores))
        (loop $exp_loop
          ;; $exp4 written out (the same operations): one call less per key
          (local.set $ex (f32x4.max (f32x4.sub (v128.load (local.get $sp)) (local.get $m)) (v128.const f32x4 -87 -87 -87 -87)))
          (local.set $ek (f32x4.nearest (f32x4.mul (local.get $ex) (v128.const f32x4 1.442695 1.442695 1.442695 1.442695))))
          (local.set $er (f32x4.sub
            (f32x4.sub (local.get $ex) (f32x4.mul (local.get $ek) (v128.const f32x4 0.693359375 0.693359375 0.693359375 0.693359375)))
            (f32x4.mul (local.get $ek) (v128.const f32x4 -2.12194440e-4 -2.12194440e-4 -2.12194440e-4 -2.12194440e-4))))
          (local.set $p (f32x4.mul
            (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (local.get $er)
            (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (local.get $er)
            (f32x4.add (v128.const f32x4 0.5 0.5 0.5 0.5) (f32x4.mul (local.get $er)
            (f32x4.add (v128.const f32x4 0.16666667 0.16666667 0.16666667 0.16666667) (f32x4.mul (local.get $er)
            (f32x4.add (v128.const f32x4 0.041666668 0.041666668 0.041666668 0.041666668) (f32x4.mul (local.get $er)
            (f32x4.add (v128.const f32x4 0.008333334 0.008333334 0.008333334 0.008333334) (f32x4.mul (local.get $er)
              (v128.const f32x4 0.0013888889 0.0013888889 0.0013888889 0.0013888889)))))))))))))
            (i32x4.shl (i32x4.add (i32x4.trunc_sat_f32x4_s (local.get $ek)) (v128.const i32x4 127 127 127 127)) (i32.const 23))))
          (v128.store (local.get $sp) (local.get $p))
          (local.set $inv (f32x4.add (local.get $inv) (local.get $p)))
          (local.set $sp (i32.add (local.get $sp) (i32.const 16)))
          (br_if $exp_loop (i32.lt_u (local.get $sp) (local.get $end))))
        (local.set $inv (f32x4.div (v128.const f32x4 1 1 1 1) (local.get $inv)))
        ;; weighted sum of the values: head h's weight times the value's lanes 8h .. 8h + 7
        (local.set $o0 (v128.const f32x4 0 0 0 0))
        (local.set $o1 (v128.const f32x4 0 0 0 0))
        (local.set $o2 (v128.const f32x4 0 0 0 0))
        (local.set $o3 (v128.const f32x4 0 0 0 0))
        (local.set $o4 (v128.const f32x4 0 0 0 0))
        (local.set $o5 (v128.const f32x4 0 0 0 0))
        (local.set $o6 (v128.const f32x4 0 0 0 0))
        (local.set $o7 (v128.const f32x4 0 0 0 0))
        (local.set $sp (local.get $scores))
        (local.set $s (local.get $k0))
        (block $summed
          (loop $value_loop
            (br_if $summed (i32.ge_u (local.get $s) (local.get $k1)))
            (local.set $p (f32x4.mul (v128.load (local.get $sp)) (local.get $inv)))
            (local.set $kp (i32.add (local.get $qkv)
              (i32.mul (i32.load (i32.add (local.get $key_index) (i32.shl (local.get $s) (i32.const 2)))) (i32.const 384))))
            (local.set $w (i8x16.shuffle 0 1 2 3 0 1 2 3 0 1 2 3 0 1 2 3 (local.get $p) (local.get $p)))
            (local.set $o0 (f32x4.add (local.get $o0) (f32x4.mul (local.get $w) (v128.load offset=256 (local.get $kp)))))
            (local.set $o1 (f32x4.add (local.get $o1) (f32x4.mul (local.get $w) (v128.load offset=272 (local.get $kp)))))
            (local.set $w (i8x16.shuffle 4 5 6 7 4 5 6 7 4 5 6 7 4 5 6 7 (local.get $p) (local.get $p)))
            (local.set $o2 (f32x4.add (local.get $o2) (f32x4.mul (local.get $w) (v128.load offset=288 (local.get $kp)))))
            (local.set $o3 (f32x4.add (local.get $o3) (f32x4.mul (local.get $w) (v128.load offset=304 (local.get $kp)))))
            (local.set $w (i8x16.shuffle 8 9 10 11 8 9 10 11 8 9 10 11 8 9 10 11 (local.get $p) (local.get $p)))
            (local.set $o4 (f32x4.add (local.get $o4) (f32x4.mul (local.get $w) (v128.load offset=320 (local.get $kp)))))
            (local.set $o5 (f32x4.add (local.get $o5) (f32x4.mul (local.get $w) (v128.load offset=336 (local.get $kp)))))
            (local.set $w (i8x16.shuffle 12 13 14 15 12 13 14 15 12 13 14 15 12 13 14 15 (local.get $p) (local.get $p)))
            (local.set $o6 (f32x4.add (local.get $o6) (f32x4.mul (local.get $w) (v128.load offset=352 (local.get $kp)))))
            (local.set $o7 (f32x4.add (local.get $o7) (f32x4.mul (local.get $w) (v128.load offset=368 (local.get $kp)))))
            (local.set $sp (i32.add (local.get $sp) (i32.const 16)))
            (local.set $s (i32.add (local.get $s) (i32.const 1)))
            (br $value_loop)))
        (local.set $op (i32.add (local.get $out) (i32.mul (local.get $t) (i32.const 128))))
        (v128.store offset=0 (local.get $op) (local.get $o0))
        (v128.store offset=16 (local.get $op) (local.get $o1))
        (v128.store offset=32 (local.get $op) (local.get $o2))
        (v128.store offset=48 (local.get $op) (local.get $o3))
        (v128.store offset=64 (local.get $op) (local.get $o4))
        (v128.store offset=80 (local.get $op) (local.get $o5))
        (v128.store offset=96 (local.get $op) (local.get $o6))
        (v128.store offset=112 (local.get $op) (local.get $o7))
        (local.set $t (i32.add (local.get $t) (i32.const 1)))
        (br $tokens_loop))))

  ;; Row-wise LayerNorm in float32 vectors: d a multiple of 4 (else the float64 version runs)
  (func (export "layer_norm") (param $x i32) (param $rows i32) (param $d i32) (param $g i32) (param $b i32) (param $out i32) (param $eps f64)
    (local $t i32) (local $i i32) (local $row i32) (local $db i32) (local $acc v128) (local $mean v128) (local $c v128)
    (local $inv v128) (local $m f32) (local $v f32)
    (if (i32.and (local.get $d) (i32.const 3))
      (then
        (call $layer_norm_f64 (local.get $x) (local.get $rows) (local.get $d) (local.get $g) (local.get $b) (local.get $out) (local.get $eps))
        (return)))
    (local.set $db (i32.shl (local.get $d) (i32.const 2)))
    (block $rows_done
      (loop $rows_loop
        (br_if $rows_done (i32.ge_u (local.get $t) (local.get $rows)))
        (local.set $row (i32.add (local.get $x) (i32.mul (local.get $t) (local.get $db))))
        (local.set $acc (v128.const f32x4 0 0 0 0))
        (local.set $i (i32.const 0))
        (loop $sum
          (local.set $acc (f32x4.add (local.get $acc) (v128.load (i32.add (local.get $row) (local.get $i)))))
          (local.set $i (i32.add (local.get $i) (i32.const 16)))
          (br_if $sum (i32.lt_u (local.get $i) (local.get $db))))
        (local.set $m (f32.div
          (f32.add (f32.add (f32x4.extract_lane 0 (local.get $acc)) (f32x4.extract_lane 1 (local.get $acc)))
                   (f32.add (f32x4.extract_lane 2 (local.get $acc)) (f32x4.extract_lane 3 (local.get $acc))))
          (f32.convert_i32_u (local.get $d))))
        (local.set $mean (f32x4.splat (local.get $m)))
        (local.set $acc (v128.const f32x4 0 0 0 0))
        (local.set $i (i32.const 0))
        (loop $sq
          (local.set $c (f32x4.sub (v128.load (i32.add (local.get $row) (local.get $i))) (local.get $mean)))
          (local.set $acc (f32x4.add (local.get $acc) (f32x4.mul (local.get $c) (local.get $c))))
          (local.set $i (i32.add (local.get $i) (i32.const 16)))
          (br_if $sq (i32.lt_u (local.get $i) (local.get $db))))
        (local.set $v (f32.div
          (f32.add (f32.add (f32x4.extract_lane 0 (local.get $acc)) (f32x4.extract_lane 1 (local.get $acc)))
                   (f32.add (f32x4.extract_lane 2 (local.get $acc)) (f32x4.extract_lane 3 (local.get $acc))))
          (f32.convert_i32_u (local.get $d))))
        (local.set $inv (f32x4.splat (f32.div (f32.const 1) (f32.sqrt (f32.add (local.get $v) (f32.demote_f64 (local.get $eps)))))))
        (local.set $i (i32.const 0))
        (loop $norm
          (v128.store (i32.add (i32.add (local.get $out) (i32.mul (local.get $t) (local.get $db))) (local.get $i))
            (f32x4.add
              (f32x4.mul
                (f32x4.mul (f32x4.sub (v128.load (i32.add (local.get $row) (local.get $i))) (local.get $mean)) (local.get $inv))
                (v128.load (i32.add (local.get $g) (local.get $i))))
              (v128.load (i32.add (local.get $b) (local.get $i)))))
          (local.set $i (i32.add (local.get $i) (i32.const 16)))
          (br_if $norm (i32.lt_u (local.get $i) (local.get $db))))
        (local.set $t (i32.add (local.get $t) (i32.const 1)))
        (br $rows_loop))))

  ;; e^x in float32 vectors, for -87 < x <= 0: x = k ln 2 + r, a degree-6 polynomial for e^r, 2^k from the
  ;; exponent bits
  (func $exp4 (param $x v128) (result v128)
    (local $k v128) (local $r v128)
    (local.set $k (f32x4.nearest (f32x4.mul (local.get $x) (v128.const f32x4 1.442695 1.442695 1.442695 1.442695))))
    (local.set $r (f32x4.sub
      (f32x4.sub (local.get $x) (f32x4.mul (local.get $k) (v128.const f32x4 0.693359375 0.693359375 0.693359375 0.693359375)))
      (f32x4.mul (local.get $k) (v128.const f32x4 -2.12194440e-4 -2.12194440e-4 -2.12194440e-4 -2.12194440e-4))))
    (f32x4.mul
      (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (local.get $r)
      (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (local.get $r)
      (f32x4.add (v128.const f32x4 0.5 0.5 0.5 0.5) (f32x4.mul (local.get $r)
      (f32x4.add (v128.const f32x4 0.16666667 0.16666667 0.16666667 0.16666667) (f32x4.mul (local.get $r)
      (f32x4.add (v128.const f32x4 0.041666668 0.041666668 0.041666668 0.041666668) (f32x4.mul (local.get $r)
      (f32x4.add (v128.const f32x4 0.008333334 0.008333334 0.008333334 0.008333334) (f32x4.mul (local.get $r)
        (v128.const f32x4 0.0013888889 0.0013888889 0.0013888889 0.0013888889)))))))))))))
      (i32x4.shl (i32x4.add (i32x4.trunc_sat_f32x4_s (local.get $k)) (v128.const i32x4 127 127 127 127)) (i32.const 23))))

  ;; GELU in place, float32 vectors: x/2 (1 + erf(x / sqrt 2)) with erf by Abramowitz & Stegun 7.1.26
  ;; (|error| < 1.5e-7, the reference decoder's and the WGSL kernel's formula); the last count % 4
  ;; values by the table (gelu_table's arguments after count)
  (func (export "gelu") (param $a i32) (param $count i32) (param $value i32) (param $slope i32) (param $range f64) (param $steps f64)
    (local $end4 i32) (local $end8 i32) (local $x v128) (local $z v128) (local $t v128) (local $y v128)
    (local $x0 v128) (local $z0 v128) (local $t0 v128) (local $q0 v128) (local $k0 v128) (local $r0 v128) (local $e0 v128) (local $y0 v128) (local $x1 v128) (local $z1 v128) (local $t1 v128) (local $q1 v128) (local $k1 v128) (local $r1 v128) (local $e1 v128) (local $y1 v128)
    (local.set $end4 (i32.add (local.get $a) (i32.shl (i32.and (local.get $count) (i32.const -4)) (i32.const 2))))
    (local.set $end8 (i32.add (local.get $a) (i32.shl (i32.and (local.get $count) (i32.const -8)) (i32.const 2))))
    ;; Eight values a turn, two vectors interleaved and e^(-z^2) written out ($exp4's arithmetic, the same
    ;; operations in the same order): the same numbers as the loop below, with the two chains overlapping.
    (block $done8
      (loop $pairs
        (br_if $done8 (i32.ge_u (local.get $a) (local.get $end8)))
        (local.set $x0 (v128.load (local.get $a)))
        (local.set $x1 (v128.load (i32.add (local.get $a) (i32.const 16))))
        (local.set $z0 (f32x4.min (f32x4.mul (f32x4.abs (local.get $x0)) (v128.const f32x4 0.70710677 0.70710677 0.70710677 0.70710677)) (v128.const f32x4 6 6 6 6)))
        (local.set $z1 (f32x4.min (f32x4.mul (f32x4.abs (local.get $x1)) (v128.const f32x4 0.70710677 0.70710677 0.70710677 0.70710677)) (v128.const f32x4 6 6 6 6)))
        (local.set $t0 (f32x4.div (v128.const f32x4 1 1 1 1) (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (v128.const f32x4 0.3275911 0.3275911 0.3275911 0.3275911) (local.get $z0)))))
        (local.set $t1 (f32x4.div (v128.const f32x4 1 1 1 1) (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (v128.const f32x4 0.3275911 0.3275911 0.3275911 0.3275911) (local.get $z1)))))
        (local.set $q0 (f32x4.neg (f32x4.mul (local.get $z0) (local.get $z0))))
        (local.set $q1 (f32x4.neg (f32x4.mul (local.get $z1) (local.get $z1))))
        (local.set $k0 (f32x4.nearest (f32x4.mul (local.get $q0) (v128.const f32x4 1.442695 1.442695 1.442695 1.442695))))
        (local.set $k1 (f32x4.nearest (f32x4.mul (local.get $q1) (v128.const f32x4 1.442695 1.442695 1.442695 1.442695))))
        (local.set $r0 (f32x4.sub (f32x4.sub (local.get $q0) (f32x4.mul (local.get $k0) (v128.const f32x4 0.693359375 0.693359375 0.693359375 0.693359375))) (f32x4.mul (local.get $k0) (v128.const f32x4 -2.12194440e-4 -2.12194440e-4 -2.12194440e-4 -2.12194440e-4))))
        (local.set $r1 (f32x4.sub (f32x4.sub (local.get $q1) (f32x4.mul (local.get $k1) (v128.const f32x4 0.693359375 0.693359375 0.693359375 0.693359375))) (f32x4.mul (local.get $k1) (v128.const f32x4 -2.12194440e-4 -2.12194440e-4 -2.12194440e-4 -2.12194440e-4))))
        (local.set $e0 (f32x4.mul
          (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (local.get $r0)
          (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (local.get $r0)
          (f32x4.add (v128.const f32x4 0.5 0.5 0.5 0.5) (f32x4.mul (local.get $r0)
          (f32x4.add (v128.const f32x4 0.16666667 0.16666667 0.16666667 0.16666667) (f32x4.mul (local.get $r0)
          (f32x4.add (v128.const f32x4 0.041666668 0.041666668 0.041666668 0.041666668) (f32x4.mul (local.get $r0)
          (f32x4.add (v128.const f32x4 0.008333334 0.008333334 0.008333334 0.008333334) (f32x4.mul (local.get $r0)
            (v128.const f32x4 0.0013888889 0.0013888889 0.0013888889 0.0013888889)))))))))))))
          (i32x4.shl (i32x4.add (i32x4.trunc_sat_f32x4_s (local.get $k0)) (v128.const i32x4 127 127 127 127)) (i32.const 23))))
        (local.set $e1 (f32x4.mul
          (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (local.get $r1)
          (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (local.get $r1)
          (f32x4.add (v128.const f32x4 0.5 0.5 0.5 0.5) (f32x4.mul (local.get $r1)
          (f32x4.add (v128.const f32x4 0.16666667 0.16666667 0.16666667 0.16666667) (f32x4.mul (local.get $r1)
          (f32x4.add (v128.const f32x4 0.041666668 0.041666668 0.041666668 0.041666668) (f32x4.mul (local.get $r1)
          (f32x4.add (v128.const f32x4 0.008333334 0.008333334 0.008333334 0.008333334) (f32x4.mul (local.get $r1)
            (v128.const f32x4 0.0013888889 0.0013888889 0.0013888889 0.0013888889)))))))))))))
          (i32x4.shl (i32x4.add (i32x4.trunc_sat_f32x4_s (local.get $k1)) (v128.const i32x4 127 127 127 127)) (i32.const 23))))
        (local.set $y0 (f32x4.sub (v128.const f32x4 1 1 1 1) (f32x4.mul (f32x4.mul (local.get $t0)
          (f32x4.add (v128.const f32x4 0.254829592 0.254829592 0.254829592 0.254829592) (f32x4.mul (local.get $t0)
          (f32x4.add (v128.const f32x4 -0.284496736 -0.284496736 -0.284496736 -0.284496736) (f32x4.mul (local.get $t0)
          (f32x4.add (v128.const f32x4 1.421413741 1.421413741 1.421413741 1.421413741) (f32x4.mul (local.get $t0)
          (f32x4.add (v128.const f32x4 -1.453152027 -1.453152027 -1.453152027 -1.453152027) (f32x4.mul (local.get $t0)
            (v128.const f32x4 1.061405429 1.061405429 1.061405429 1.061405429))))))))))
          (local.get $e0))))
        (local.set $y1 (f32x4.sub (v128.const f32x4 1 1 1 1) (f32x4.mul (f32x4.mul (local.get $t1)
          (f32x4.add (v128.const f32x4 0.254829592 0.254829592 0.254829592 0.254829592) (f32x4.mul (local.get $t1)
          (f32x4.add (v128.const f32x4 -0.284496736 -0.284496736 -0.284496736 -0.284496736) (f32x4.mul (local.get $t1)
          (f32x4.add (v128.const f32x4 1.421413741 1.421413741 1.421413741 1.421413741) (f32x4.mul (local.get $t1)
          (f32x4.add (v128.const f32x4 -1.453152027 -1.453152027 -1.453152027 -1.453152027) (f32x4.mul (local.get $t1)
            (v128.const f32x4 1.061405429 1.061405429 1.061405429 1.061405429))))))))))
          (local.get $e1))))
        (local.set $y0 (v128.bitselect (f32x4.neg (local.get $y0)) (local.get $y0) (f32x4.lt (local.get $x0) (v128.const f32x4 0 0 0 0))))
        (local.set $y1 (v128.bitselect (f32x4.neg (local.get $y1)) (local.get $y1) (f32x4.lt (local.get $x1) (v128.const f32x4 0 0 0 0))))
        (v128.store (local.get $a) (f32x4.mul (f32x4.mul (v128.const f32x4 0.5 0.5 0.5 0.5) (local.get $x0)) (f32x4.add (v128.const f32x4 1 1 1 1) (local.get $y0))))
        (v128.store (i32.add (local.get $a) (i32.const 16)) (f32x4.mul (f32x4.mul (v128.const f32x4 0.5 0.5 0.5 0.5) (local.get $x1)) (f32x4.add (v128.const f32x4 1 1 1 1) (local.get $y1))))
        (local.set $a (i32.add (local.get $a) (i32.const 32)))
        (br $pairs)))
    (block $done
      (loop $each
        (br_if $done (i32.ge_u (local.get $a) (local.get $end4)))
        (local.set $x (v128.load (local.get $a)))
        ;; z = min(|x| / sqrt 2, 6): erf(6) is 1 in float32
        (local.set $z (f32x4.min (f32x4.mul (f32x4.abs (local.get $x)) (v128.const f32x4 0.70710677 0.70710677 0.70710677 0.70710677))
                                 (v128.const f32x4 6 6 6 6)))
        (local.set $t (f32x4.div (v128.const f32x4 1 1 1 1)
          (f32x4.add (v128.const f32x4 1 1 1 1) (f32x4.mul (v128.const f32x4 0.3275911 0.3275911 0.3275911 0.3275911) (local.get $z)))))
        ;; y = 1 - t (a1 + t (a2 + t (a3 + t (a4 + t a5)))) e^(-z^2)
        (local.set $y (f32x4.sub (v128.const f32x4 1 1 1 1) (f32x4.mul
          (f32x4.mul (local.get $t)
            (f32x4.add (v128.const f32x4 0.254829592 0.254829592 0.254829592 0.254829592) (f32x4.mul (local.get $t)
            (f32x4.add (v128.const f32x4 -0.284496736 -0.284496736 -0.284496736 -0.284496736) (f32x4.mul (local.get $t)
            (f32x4.add (v128.const f32x4 1.421413741 1.421413741 1.421413741 1.421413741) (f32x4.mul (local.get $t)
            (f32x4.add (v128.const f32x4 -1.453152027 -1.453152027 -1.453152027 -1.453152027) (f32x4.mul (local.get $t)
              (v128.const f32x4 1.061405429 1.061405429 1.061405429 1.061405429))))))))))
          (call $exp4 (f32x4.neg (f32x4.mul (local.get $z) (local.get $z)))))))
        ;; erf takes the sign of x
        (local.set $y (v128.bitselect (f32x4.neg (local.get $y)) (local.get $y) (f32x4.lt (local.get $x) (v128.const f32x4 0 0 0 0))))
        (v128.store (local.get $a)
          (f32x4.mul (f32x4.mul (v128.const f32x4 0.5 0.5 0.5 0.5) (local.get $x)) (f32x4.add (v128.const f32x4 1 1 1 1) (local.get $y))))
        (local.set $a (i32.add (local.get $a) (i32.const 16)))
        (br $each)))
    (call $gelu_table (local.get $a) (i32.and (local.get $count) (i32.const 3))
      (local.get $value) (local.get $slope) (local.get $range) (local.get $steps)))
)

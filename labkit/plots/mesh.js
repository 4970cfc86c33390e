// The patch editor's mesh drawn in the page while a handle moves (editor.js; the kernel puts scene.js and this
// file before it). A drag's picture need not wait for the kernel: the Coons patch is a sum of Hermite cubics of
// the corner data, so with the basis at the mesh's parameter values, the axes' transform and the colour map
// (the editor's `sketch`, from labkit.plots.editor.Editor._sketch) the page computes the mesh, each element's
// quality and the title as the kernel does (labkit.patches.patch, labkit.mesh.QuadMesh.quality, matplotlib's
// colour mapping) and builds the same scene items, to rounding (NumPy's products may fuse a multiply and an add).
// The kernel's own picture of the drag follows and is drawn over it. tests/browser/test_mesh_sketch.py compares
// the two, item by item, in Chromium.

// Python's f"{x:.2f}": toFixed(2) but for -0 and for ties (x an odd multiple of 1/8, exact in binary), which
// Python rounds to the even neighbour and toFixed away from zero
function meshFixed2(x) {
  if (Object.is(x, -0)) return "-0.00";
  const a = Math.abs(x);
  if (Number.isInteger(a * 8) && !Number.isInteger(a * 4)) {
    const low = Math.floor(a * 100);
    return (x < 0 ? "-" : "") + ((low % 2 === 0 ? low : low + 1) / 100).toFixed(2);
  }
  return x.toFixed(2);
}

// the corners after handle `index` is dropped at `point` (labkit.plots.editor.move_handle): each corner is
// [x, y, ds_x, ds_y, dt_x, dt_y, twist_x, twist_y]; a corner carries its arrows along, a tip sets its derivative
function meshMove(corners, index, point, arrow) {
  const moved = corners.map((c) => c.slice());
  const c = moved[index % 4], kind = Math.floor(index / 4);
  if (kind === 0) { c[0] = point[0]; c[1] = point[1]; }
  else { const at = 2 * kind; c[at] = (point[0] - c[0]) / arrow; c[at + 1] = (point[1] - c[1]) / arrow; }
  return moved;
}

// the mesh of `corners` as the kernel's scene items (PatchView.dynamic's order: elements, title, folded
// elements), and its worst quality
function meshItems(sketch, corners) {
  const S = sceneFloats(sketch.in_s, Float64Array), T = sceneFloats(sketch.in_t, Float64Array);
  const ns = S.length / 4, nt = T.length / 4;
  const [A, B, C, D] = corners;
  // a Hermite cubic in s of (left value, left slope, right value, right slope) at offsets into two corners
  const cubic = (left, l, right, r, d, i) =>
    left[l + d] * S[i] + left[l + 2 + d] * S[ns + i] + right[r + d] * S[2 * ns + i] + right[r + 2 + d] * S[3 * ns + i];
  const x = new Float64Array(ns * nt), y = new Float64Array(ns * nt);
  for (let d = 0; d < 2; d++) {
    const out = d === 0 ? x : y;
    for (let i = 0; i < ns; i++) {
      const bottom = cubic(A, 0, B, 0, d, i), bottomDt = cubic(A, 4, B, 4, d, i);
      const top = cubic(D, 0, C, 0, d, i), topDt = cubic(D, 4, C, 4, d, i);
      for (let j = 0; j < nt; j++)
        out[i * nt + j] = bottom * T[j] + bottomDt * T[nt + j] + top * T[2 * nt + j] + topDt * T[3 * nt + j];
    }
  }
  const [a, c, e, b, dd, f] = sketch.matrix, height = sketch.height;
  const ne = (ns - 1) * (nt - 1);
  const xy = new Float32Array(10 * ne), faces = new Uint8Array(4 * ne), quality = new Float64Array(ne);
  const colors = sceneBytes(sketch.colors), N = sketch.n_colors, vmin = sketch.vmin, vmax = sketch.vmax;
  const px = [0, 0, 0, 0], py = [0, 0, 0, 0];
  let worst = Infinity, folded = 0;
  for (let i = 0; i < ns - 1; i++) {
    for (let j = 0; j < nt - 1; j++) {
      const k = i * (nt - 1) + j;
      const nodes = [i * nt + j, (i + 1) * nt + j, (i + 1) * nt + j + 1, i * nt + j + 1];
      for (let v = 0; v < 5; v++) { // four corners, then the first again (a closed path)
        const n = nodes[v % 4];
        xy[10 * k + 2 * v] = a * x[n] + c * y[n] + e;
        xy[10 * k + 2 * v + 1] = height - (b * x[n] + dd * y[n] + f);
      }
      for (let v = 0; v < 4; v++) { px[v] = x[nodes[v]]; py[v] = y[nodes[v]]; }
      let q = Infinity;
      for (let v = 0; v < 4; v++) { // the scaled Jacobian at each corner: its two edges' signed area over their lengths
        const fx = px[(v + 1) % 4] - px[v], fy = py[(v + 1) % 4] - py[v];
        const bx = px[(v + 3) % 4] - px[v], by = py[(v + 3) % 4] - py[v];
        const lengths = Math.sqrt(fx * fx + fy * fy) * Math.sqrt(bx * bx + by * by);
        q = Math.min(q, lengths > 0 ? (fx * by - fy * bx) / lengths : 0);
      }
      q = Math.min(1, Math.max(-1, q));
      quality[k] = q;
      worst = Math.min(worst, q);
      if (q <= 0) folded += 1;
      // matplotlib's colour mapping: normalised, times N, the top end into the last colour, then truncated
      let at = ((q - vmin) / (vmax - vmin)) * N;
      if (at === N) at = N - 1;
      const index = at < 0 ? N : at >= N ? N + 1 : Math.trunc(at);
      faces.set(colors.subarray(4 * index, 4 * index + 4), 4 * k);
    }
  }
  const hatched = new Float32Array(10 * folded);
  for (let k = 0, h = 0; k < ne; k++) if (quality[k] <= 0) hatched.set(xy.subarray(10 * k, 10 * k + 10), 10 * h++);
  return {
    worst,
    items: [
      { ...sketch.cells, xy, counts: new Array(ne).fill(5), faces, face_count: ne },
      { ...sketch.title, text: sketch.title.text.replace("{worst}", meshFixed2(worst)) },
      { ...sketch.folded, xy: hatched, counts: new Array(folded).fill(5) },
    ],
  };
}

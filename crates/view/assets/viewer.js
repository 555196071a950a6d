// glassdb view: the composite of compose (method.md eqs. 8-10) on the GPU with WebGL2.
// Data: from the server (/api/...) or, in an exported folder, from the scripts data.js and
// frame-NNNN.js (browsers refuse fetch() of local files). Layouts: crates/view/src/data.rs.
'use strict';

(function () {
  const EXPORT = window.GLASSDB_EXPORT;
  const $ = (id) => document.getElementById(id);
  const canvas = $('view-canvas');
  const errors = [];
  window.glassdbErrors = errors;

  function status(text, isError) {
    const s = $('status');
    s.textContent = text;
    s.className = isError ? 'error' : '';
    if (isError) errors.push(text);
  }

  // ---- data sources ------------------------------------------------------------------------

  function base64Bytes(text) {
    const bin = atob(text);
    const out = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
    return out.buffer;
  }

  // An export's data (crates/view/src/export.rs, packed_base64): RGBA texels of 2- or 4-byte
  // elements, each the difference from the same channel of the texel before, their bytes
  // gathered by position (byte 0 of every element, then byte 1, …), gzip, base64. Undone here,
  // the browser's own DecompressionStream inflating it.
  async function packedBytes(text, elementBytes) {
    const stream = new Blob([base64Bytes(text)]).stream().pipeThrough(new DecompressionStream('gzip'));
    const packed = new Uint8Array(await new Response(stream).arrayBuffer());
    const n = packed.length / elementBytes;
    const out = new Uint8Array(packed.length);
    for (let b = 0; b < elementBytes; b++) {
      const plane = packed.subarray(b * n, (b + 1) * n);
      for (let i = 0; i < n; i++) out[i * elementBytes + b] = plane[i];
    }
    // Typed arrays wrap on store, as the differences did.
    const values = elementBytes === 4 ? new Uint32Array(out.buffer) : new Uint16Array(out.buffer);
    for (let i = 4; i < values.length; i++) values[i] += values[i - 4];
    return out.buffer;
  }

  function loadScript(src) {
    return new Promise((resolve, reject) => {
      const s = document.createElement('script');
      s.src = src;
      s.onload = resolve;
      s.onerror = () => reject(new Error('cannot load ' + src));
      document.head.appendChild(s);
    });
  }

  async function fetchOk(url, kind) {
    const r = await fetch(url);
    if (!r.ok) {
      let message = r.status + ' ' + r.statusText;
      try { message = (await r.json()).error || message; } catch (e) { /* not JSON */ }
      throw new Error(url + ': ' + message);
    }
    return kind === 'json' ? r.json() : r.arrayBuffer();
  }

  // The page's data (crates/view/src/page.rs), from the server or from an export: read here
  // only, so that every field the page uses comes through one place that knows its version.
  const PAGE_FORMAT = 'glassdb-viewer-page/4';

  function readScene(scene) {
    if (!scene || scene.format !== PAGE_FORMAT) {
      throw new Error('the page data is ' + (scene && scene.format) + ', not ' + PAGE_FORMAT
        + ': serve or export it with the glassdb of this page');
    }
    return scene;
  }

  // `parts`: the light parts' passes, part after part, packed (data.rs, part_bytes; empty
  // without a light-path split).
  // `passes`: the transmission, each plane's reflection, then each pane group's (`groups`:
  // {plane, group}, in that order; `groups_folded`: why a frame's groups are not apart).
  function readFrame(info, passes, mask, parts) {
    return { info: { ids: info.ids, trans: info.trans, plane_sides: info.plane_sides, parts: info.parts || [],
      groups: info.groups || [], groupsFolded: info.groups_folded || null }, passes, mask,
      parts: parts || new Uint32Array(0) };
  }

  // A unit the server built (POST api/unit): its product and its table.
  function readBuiltUnit(built) {
    if (!built || built.format !== PAGE_FORMAT) throw new Error('the unit data is not ' + PAGE_FORMAT);
    return { product: built.product, lut: new Float32Array(base64Bytes(built.lut)), buildMs: built.build_ms };
  }

  const source = EXPORT ? {
    scene: async () => readScene(EXPORT.scene),
    luts: async () => Promise.all(EXPORT.luts.map(async (text) => new Float32Array(await packedBytes(text, 4)))),
    view: async (i) => new Float32Array(base64Bytes(EXPORT.views[i])),
    frame: async (i) => {
      if (!EXPORT.frames[i]) await loadScript(window.GLASSDB_EXPORT_FRAME_FILES[i]);
      const f = EXPORT.frames[i];
      return readFrame(f.info, new Uint16Array(await packedBytes(f.passes, 2)), new Float32Array(await packedBytes(f.mask, 4)),
        f.parts ? new Uint32Array(await packedBytes(f.parts, 4)) : undefined);
    },
  } : {
    scene: async () => readScene(await fetchOk('api/scene', 'json')),
    // One request for every table, and a frame's parts one after the other: the page keeps to
    // one connection.
    luts: async (n) => {
      const all = await fetchOk('api/luts');
      const size = all.byteLength / n;
      return Array.from({ length: n }, (_, i) => new Float32Array(all, i * size, size / 4));
    },
    view: async (i) => new Float32Array(await fetchOk('api/view/' + i)),
    frame: async (i) => {
      const info = await fetchOk('api/frame/' + i, 'json');
      const passes = await fetchOk('api/frame/' + i + '/passes');
      const mask = await fetchOk('api/frame/' + i + '/mask');
      const parts = info.parts && info.parts.length ? new Uint32Array(await fetchOk('api/frame/' + i + '/parts')) : undefined;
      return readFrame(info, new Uint16Array(passes), new Float32Array(mask), parts);
    },
  };

  // ---- product names (the `glass` parameter: ID:PRODUCT,...) ---------------------------------

  // Splits at the commas an `ID:` follows (product names may hold commas).
  function splitChoices(spec) {
    const parts = [];
    let start = 0;
    for (let i = 0; i < spec.length; i++) {
      if (spec[i] === ',' && /^\s*\d+:/.test(spec.slice(i + 1))) {
        parts.push(spec.slice(start, i));
        start = i + 1;
      }
    }
    parts.push(spec.slice(start));
    return parts.filter((p) => p.trim() !== '');
  }

  // A product's full name (any case), its registry id, or a part of one name only.
  function findProduct(products, name) {
    const lower = name.trim().toLowerCase();
    let i = products.findIndex((p) => p.name.toLowerCase() === lower);
    if (i >= 0) return i;
    if (/^\d+$/.test(lower)) {
      i = products.findIndex((p) => p.id === Number(lower));
      if (i >= 0) return i;
    }
    const matches = products.filter((p) => p.name.toLowerCase().includes(lower));
    if (matches.length === 1) return matches[0].index;
    throw new Error(matches.length === 0 ? 'no product matches "' + name + '"'
      : '"' + name + '" matches several products: ' + matches.map((p) => p.name).join('; '));
  }

  function parseChoices(products, slots, spec) {
    const out = [];
    for (const part of splitChoices(spec)) {
      const colon = part.indexOf(':');
      const id = Number(part.slice(0, colon));
      if (colon < 0 || !Number.isInteger(id) || slots.indexOf(id) < 0) {
        throw new Error('glass choice "' + part + '": expected ID:PRODUCT with an id of the registry');
      }
      out.push([id, findProduct(products, part.slice(colon + 1))]);
    }
    return out;
  }

  // ---- half floats and colour for the page's own numbers ------------------------------------

  function halfToFloat(h) {
    const s = (h & 0x8000) ? -1 : 1;
    const e = (h >> 10) & 0x1f;
    const m = h & 0x3ff;
    if (e === 0) return s * m * Math.pow(2, -24);
    if (e === 31) return m ? NaN : s * Infinity;
    return s * (1 + m / 1024) * Math.pow(2, e - 15);
  }

  function srgbEncode(c) {
    c = Math.min(1, Math.max(0, c || 0));
    return c <= 0.0031308 ? c * 12.92 : 1.055 * Math.pow(c, 1 / 2.4) - 0.055;
  }

  // ---- WebGL2 -------------------------------------------------------------------------------

  const VERTEX = `#version 300 es
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}`;

  // The plain shader's mask and passes (a frame without light parts).
  const plainMask = `  vec4 m = texelFetch(uMask, ivec2(x, y), 0);
  int slot = int(m.r + 0.5) - 1;
  int plane = int(m.g + 0.5);
  bool glass = slot >= 0 && plane < uPlanes;`;
  const plainPasses = `  vec4 t4 = texelFetch(uTrans, ivec2(x, y), 0);
  tr = t4.rgb;
  alpha = t4.a;
  if (glass) {
    rf0 = texelFetch(uRefl, ivec3(x, y, layer.x), 0).rgb;
    if (ghosts && layer.y != layer.x) rf1 = texelFetch(uRefl, ivec3(x, y, layer.y), 0).rgb;
    if (n > 2 && layer.z != layer.y) rf2 = texelFetch(uRefl, ivec3(x, y, layer.z), 0).rgb;
  }`;

  // The fixed sums' layers per set (fixedSource): the transmission, then the reflection of the
  // pixel's plane, and with pane-group passes its groups 1 and 2.
  const fixedLayers = (layers) => (layers === 2 ? 4 : 2);
  // Without pane-group passes, up to two active parts are gathered by the fixed pass into two
  // texels after both sets' layers (set-independent, copies of their halves): their
  // transmissions and reflections' red in one (words x, y of the first part, z, w of the
  // second), the rest of their reflections with the mask's coverage and cos θ in the other, so
  // that a pixel reads 2 texels off glass and 4 on glass (and the tables), not one per part.
  const gathers = (relit) => relit.layers === 1 && relit.active.length <= 2;

  // The relit shader's mask: the pixel's glass slot and plane from the fixed sums' first texel
  // (its fourth word), so that a pixel off glass reads no mask texel.
  function relitMask(relit) {
    const per = fixedLayers(relit.layers);
    const text = `  int base = useB ? ${per} : 0;
  uvec4 fixed0 = texelFetch(uFixed, ivec3(x, y, base), 0);
  int slot = int(fixed0.w & 0xffffu) - 1;
  int plane = int(fixed0.w >> 16);
  bool glass = slot >= 0 && plane < uPlanes;
  vec4 m = vec4(0.0);`;
    if (!gathers(relit)) return text + '\n  if (glass) m = texelFetch(uMask, ivec2(x, y), 0);';
    return text + `
  uvec4 gt = ${relit.active.length ? `texelFetch(uFixed, ivec3(x, y, ${2 * per}), 0)` : 'uvec4(0u)'};
  uvec4 gr = uvec4(0u);
  if (glass) {
    gr = texelFetch(uFixed, ivec3(x, y, ${2 * per + 1}), 0);
    m = vec4(0.0, 0.0, uintBitsToFloat(gr.w), uintBitsToFloat(gr.z));
  }`;
  }

  // One light part's passes (part_bytes) added with factor `f`: `p` its index, `layers` per part;
  // `all`: every pass whatever the pixel (the fixed sums), else only what the pixel composites.
  function addPart(p, layers, f, all) {
    const at = (l) => `texelFetch(uParts, ivec3(xy, ${p * layers + l}), 0)`;
    const when = (cond, text) => (all ? text : `if (${cond}) ${text}`);
    let text = `  {
    vec3 f = ${f};
    uvec4 a = ${at(0)};
    vec2 a1 = unpackHalf2x16(a.y);
    tr += f * vec3(unpackHalf2x16(a.x), a1.x);
    ${when('glass', '{')}
      rf0 += f * vec3(a1.y, unpackHalf2x16(a.z));`;
    if (layers === 2) {
      text += `
      ${when('ghosts', '{')}
        uvec4 b = ${at(1)};
        vec2 b1 = unpackHalf2x16(b.y);
        ${when('layer.y != layer.x', '')}rf1 += f * vec3(unpackHalf2x16(b.x), b1.x);
        ${when('n > 2 && layer.z != layer.y', '')}rf2 += f * vec3(b1.y, unpackHalf2x16(b.z));
      }`;
    }
    return text + `
    }
  }
`;
  }

  // The relit shader's passes: the fixed sums of the parts a choice does not change, plus each
  // part it does (`relit.active`, indices of the frame's parts), written out one by one (a loop
  // over the parts costs SwiftShader about a third more; docs/performance.md, "Relit swap").
  function relitSums(relit) {
    let text = `  ivec2 xy = ivec2(x, y);
  tr = uintBitsToFloat(fixed0.xyz);
  if (glass) {
    rf0 = uintBitsToFloat(texelFetch(uFixed, ivec3(xy, base + 1), 0).xyz);`;
    if (relit.layers === 2) {
      text += `
    if (ghosts && layer.y != layer.x) rf1 = uintBitsToFloat(texelFetch(uFixed, ivec3(xy, base + 2), 0).xyz);
    if (n > 2 && layer.z != layer.y) rf2 = uintBitsToFloat(texelFetch(uFixed, ivec3(xy, base + 3), 0).xyz);`;
    }
    text += '\n  }\n';
    const factor = (k) => `useB ? uFactorB[${k}] : uFactorA[${k}]`;
    if (!gathers(relit)) {
      relit.active.forEach((p, k) => { text += addPart(p, relit.layers, factor(k), false); });
      return text;
    }
    relit.active.forEach((_, k) => {
      text += `  {
    vec3 f = ${factor(k)};
    vec2 a1 = unpackHalf2x16(gt.${'yw'[k]});
    tr += f * vec3(unpackHalf2x16(gt.${'xz'[k]}), a1.x);
    if (glass) rf0 += f * vec3(a1.y, unpackHalf2x16(gr.${'xy'[k]}));
  }
`;
    });
    return text;
  }

  // The sums of the parts `rest` (indices) with their factors of one set (uFactor), drawn into
  // the fixed layers of that set as f32 bits (exact, unlike halves), the transmission's texel
  // carrying the mask's glass slot + 1 and plane (low and high 16 bits).
  // `gather`: the active parts to gather (see `gathers`), or null.
  function fixedSource(rest, layers, gather) {
    const outs = ['oTr', 'oRf0', 'oRf1', 'oRf2'].slice(0, fixedLayers(layers)).concat(gather ? ['oGT', 'oGR'] : []);
    let text = `#version 300 es
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp usampler2DArray;
uniform highp usampler2DArray uParts;
uniform sampler2D uMask;
uniform vec3 uFactor[16];
${outs.map((o, k) => `layout(location = ${k}) out uvec4 ${o};`).join('\n')}
void main() {
  // Rows as the data's (top to bottom): the target is read as the parts are.
  ivec2 xy = ivec2(gl_FragCoord.xy);
  vec4 m = texelFetch(uMask, xy, 0);
  vec3 tr = vec3(0.0);
  vec3 rf0 = vec3(0.0);
  vec3 rf1 = vec3(0.0);
  vec3 rf2 = vec3(0.0);
`;
    rest.forEach((p, k) => { text += addPart(p, layers, `uFactor[${k}]`, true); });
    text += `  oTr = uvec4(floatBitsToUint(tr), uint(int(m.r + 0.5)) | (uint(int(m.g + 0.5)) << 16));
  oRf0 = uvec4(floatBitsToUint(rf0), 0u);
`;
    if (layers === 2) text += '  oRf1 = uvec4(floatBitsToUint(rf1), 0u);\n  oRf2 = uvec4(floatBitsToUint(rf2), 0u);\n';
    if (gather) {
      const part = (k) => (k < gather.length ? `texelFetch(uParts, ivec3(xy, ${gather[k]}), 0)` : 'uvec4(0u)');
      text += `  uvec4 g0 = ${part(0)};
  uvec4 g1 = ${part(1)};
  oGT = uvec4(g0.xy, g1.xy);
  oGR = uvec4(g0.z, g1.z, floatBitsToUint(m.a), floatBitsToUint(m.b));
`;
    }
    return text + '}';
  }

  // `relit`: null for the plain shader, or for a frame with light parts {active, layers}: the
  // parts a choice re-weights (those of the active glass id) and the layers per part.
  function fragmentSource(lut, relit) {
    return `#version 300 es
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp sampler2DArray;
precision highp sampler3D;
uniform sampler2D uTrans;
uniform sampler2DArray uRefl;
uniform sampler2D uMask;
uniform sampler2D uLutA;
uniform sampler2D uLutB;
uniform int uHeight;
uniform int uMode;      // 0: 8-bit code, 1: cos, 2: normal incidence
uniform int uPlanes;
uniform int uSide[64];  // 0 front, 1 back, per plane
// Per plane: the uRefl layer of its pane groups 1 and 2 (-1: none; the group's share then
// goes to the deepest nearer group's pass, as compose folds it).
uniform ivec2 uGroupLayer[64];
uniform float uGain;    // 2^ev
uniform bool uConvert;
uniform mat3 uDisplay;  // passes' space to linear Rec.709
uniform int uAB;        // 0: A, 1: B, 2: split
uniform float uSplitX;  // split position in pixels
uniform int uView;      // 0: standard, 1: a .cube view
uniform sampler2D uShaper;
uniform highp sampler3D uCube;
uniform bool uHasShaper;
uniform bool uHasCube;
uniform int uShaperLen;
uniform vec3 uShaperScale;
uniform vec3 uShaperOffset;
uniform int uCubeN;
uniform vec3 uCubeScale;
uniform vec3 uCubeOffset;
// The relit swap (docs/viewer.md, "Relit swap"): each light part's passes, part after part,
// packed as halves (crates/view/src/data.rs, part_bytes: the transmission and the pixel's
// plane's reflection in one texel, its pane groups' in a second); the sums of the parts a choice
// does not change, per set (fixedSource), and the factor of each part it does change, per set:
// what the glass its light came through passes, times its exposure.
uniform highp usampler2DArray uParts;
uniform highp usampler2DArray uFixed;
uniform vec3 uFactorA[16];
uniform vec3 uFactorB[16];
out vec4 outColor;
const int W = ${lut.width};
const int ROWS_CURVE = ${lut.rows_per_curve};
const int ROWS_SLOT = ${lut.rows_per_slot};
const int FINE = ${lut.fine_offset};
const int STEPS = ${lut.fine_steps};
const int NORMAL = ${lut.normal_offset};
const int GROUPS = ${lut.groups};

// a + f·(b − a), as compose's lerp (not GLSL's mix, whose rounding may differ).
vec3 mix3(vec3 a, vec3 b, float f) {
  return a + f * (b - a);
}

vec3 entry(sampler2D lut, int row, int e) {
  return texelFetch(lut, ivec2(e % W, row + e / W), 0).rgb;
}

// r and t exactly as compose's GlassSideLut: at_code8, at_cos (linear in the fine table), normal.
void lookup(sampler2D lut, int slot, int side, float c, out vec3 r, out vec3 t) {
  int rRow = slot * ROWS_SLOT + side * 2 * ROWS_CURVE;
  int tRow = rRow + ROWS_CURVE;
  if (uMode == 0) {
    int e = int(c + 0.5);
    r = entry(lut, rRow, e);
    t = entry(lut, tRow, e);
  } else if (uMode == 1) {
    float x = clamp(c, 0.0, 1.0) * float(STEPS);
    int i = min(int(x), STEPS - 1);
    float f = x - float(i);
    vec3 r0 = entry(lut, rRow, FINE + i);
    vec3 t0 = entry(lut, tRow, FINE + i);
    r = r0 + (entry(lut, rRow, FINE + i + 1) - r0) * f;
    t = t0 + (entry(lut, tRow, FINE + i + 1) - t0) * f;
  } else {
    r = entry(lut, rRow, NORMAL);
    t = entry(lut, tRow, NORMAL);
  }
}

// Pane group g's share of r (compose's ShareSideLut), as lookup reads r.
vec3 share(sampler2D lut, int slot, int side, int g, float c) {
  int row = slot * ROWS_SLOT + (4 + side * GROUPS + g) * ROWS_CURVE;
  if (uMode == 0) return entry(lut, row, int(c + 0.5));
  if (uMode == 1) {
    float x = clamp(c, 0.0, 1.0) * float(STEPS);
    int i = min(int(x), STEPS - 1);
    float f = x - float(i);
    vec3 a = entry(lut, row, FINE + i);
    return a + (entry(lut, row, FINE + i + 1) - a) * f;
  }
  return entry(lut, row, NORMAL);
}

// The glass's pane groups (the front r curve's normal-incidence alpha).
int groupCount(sampler2D lut, int slot) {
  return int(texelFetch(lut, ivec2(NORMAL % W, slot * ROWS_SLOT + NORMAL / W), 0).a + 0.5);
}

vec3 srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  vec3 lo = c * 12.92;
  vec3 hi = 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055;
  return mix(hi, lo, vec3(lessThanEqual(c, vec3(0.0031308))));
}

// A table's index of x, as compose's CubeLut: (x·scale + offset)·last, NaN → 0, clamped.
float tableIndex(float x, float last) {
  float v = x * last;
  return isnan(v) ? 0.0 : clamp(v, 0.0, last);
}

vec3 shaperAt(int i) {
  return texelFetch(uShaper, ivec2(i % W, i / W), 0).rgb;
}

// compose's CubeLut::apply: the 1D table per channel (linear), then the 3D table (trilinear).
vec3 cubeView(vec3 v) {
  if (uHasShaper) {
    float last = float(uShaperLen - 1);
    for (int c = 0; c < 3; c++) {
      float f = tableIndex(v[c] * uShaperScale[c] + uShaperOffset[c], last);
      int lo = min(int(floor(f)), uShaperLen - 1);
      int hi = min(lo + 1, uShaperLen - 1);
      float d = f - float(lo);
      float a = shaperAt(lo)[c];
      float b = shaperAt(hi)[c];
      v[c] = a + d * (b - a);
    }
  }
  if (uHasCube) {
    float last = float(uCubeN - 1);
    ivec3 lo;
    ivec3 hi;
    vec3 d;
    for (int c = 0; c < 3; c++) {
      float f = tableIndex(v[c] * uCubeScale[c] + uCubeOffset[c], last);
      lo[c] = min(int(floor(f)), uCubeN - 1);
      hi[c] = min(lo[c] + 1, uCubeN - 1);
      d[c] = f - float(lo[c]);
    }
    vec3 c00 = mix3(texelFetch(uCube, ivec3(lo.x, lo.y, lo.z), 0).rgb, texelFetch(uCube, ivec3(hi.x, lo.y, lo.z), 0).rgb, d.x);
    vec3 c10 = mix3(texelFetch(uCube, ivec3(lo.x, hi.y, lo.z), 0).rgb, texelFetch(uCube, ivec3(hi.x, hi.y, lo.z), 0).rgb, d.x);
    vec3 c01 = mix3(texelFetch(uCube, ivec3(lo.x, lo.y, hi.z), 0).rgb, texelFetch(uCube, ivec3(hi.x, lo.y, hi.z), 0).rgb, d.x);
    vec3 c11 = mix3(texelFetch(uCube, ivec3(lo.x, hi.y, hi.z), 0).rgb, texelFetch(uCube, ivec3(hi.x, hi.y, hi.z), 0).rgb, d.x);
    v = mix3(mix3(c00, c10, d.y), mix3(c01, c11, d.y), d.z);
  }
  return v;
}

void main() {
  int x = int(gl_FragCoord.x);
  int y = uHeight - 1 - int(gl_FragCoord.y);
  bool useB = uAB == 1 || (uAB == 2 && float(x) >= uSplitX);
${relit ? relitMask(relit) : plainMask}
  // A unit on a plane with pane-group passes reflects once per group (docs/viewer.md, "Units
  // and their ghosts"): the uRefl layer of each of its groups' reflections, a group without a
  // pass of its own taking the deepest nearer group's (as compose folds it).
  int n = 1;
  ivec3 layer = ivec3(plane);
  ivec2 gls = glass ? uGroupLayer[plane] : ivec2(-1);
  if (gls.x >= 0 || gls.y >= 0) {
    n = useB ? groupCount(uLutB, slot) : groupCount(uLutA, slot);
    layer.y = gls.x >= 0 ? gls.x : layer.x;
    layer.z = gls.y >= 0 ? gls.y : layer.y;
  }
  bool ghosts = n > 1;
  // The transmission and each group's reflection: the passes, or with light parts
  // Σ_p f_p·pass_p (the composite is linear in the passes).
  vec3 tr = vec3(0.0);
  float alpha = 1.0;
  vec3 rf0 = vec3(0.0);
  vec3 rf1 = vec3(0.0);
  vec3 rf2 = vec3(0.0);
${relit ? relitSums(relit) : plainPasses}
  if (layer.y == layer.x) rf1 = rf0;
  if (layer.z == layer.y) rf2 = rf1;
  vec3 col = tr;
  if (glass) {
    vec3 r;
    vec3 t;
    if (useB) {
      lookup(uLutB, slot, uSide[plane], m.b, r, t);
    } else {
      lookup(uLutA, slot, uSide[plane], m.b, r, t);
    }
    float k = m.a;
    t = 1.0 - k + k * t;
    if (ghosts) {
      // Σ_g refl_g · r_g, in compose's order.
      vec3 sum = vec3(0.0);
      for (int g = 0; g < GROUPS; g++) {
        if (g >= n) break;
        vec3 s = useB ? share(uLutB, slot, uSide[plane], g, m.b) : share(uLutA, slot, uSide[plane], g, m.b);
        vec3 pass = g == 0 ? rf0 : (g == 1 ? rf1 : rf2);
        sum += pass * (s * k);
      }
      col = tr * t + sum;
    } else {
      col = tr * t + rf0 * (r * k);
    }
  }
  col *= uGain;
  if (uConvert && uView == 0) col = uDisplay * col;
  if (alpha > 0.0) col /= alpha;
  if (uView == 0) {
    outColor = vec4(srgb(col), 1.0);
  } else {
    vec3 v = cubeView(col);
    outColor = vec4(mix(clamp(v, 0.0, 1.0), vec3(0.0), vec3(isnan(v))), 1.0);
  }
}`;
  }

  function compile(gl, type, text) {
    const s = gl.createShader(type);
    gl.shaderSource(s, text);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }

  function texture(gl, target) {
    const t = gl.createTexture();
    gl.bindTexture(target, t);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(target, p, gl.NEAREST);
    gl.texParameteri(target, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(target, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    return t;
  }

  // ---- the viewer ---------------------------------------------------------------------------

  async function main() {
    const scene = await source.scene();
    const W = scene.width, H = scene.height;
    const products = scene.products;
    const slots = scene.slots;
    const lutLayout = scene.lut;
    const slotFloats = lutLayout.rows_per_slot * lutLayout.width * 4;
    canvas.width = W;
    canvas.height = H;

    // ---- the frame on screen: fitted to the stage (the default), or zoomed ----
    const params = new URLSearchParams(location.search);
    const stage = $('stage');
    const frameBox = $('frame-box');
    const zoom = { fit: true, scale: 1 };
    const fitScale = () => Math.max(1 / 64, Math.min(stage.clientWidth / W, stage.clientHeight / H));
    // `anchor`: a point on screen [x, y] that stays over the same frame pixel (the wheel's).
    function applyZoom(anchor) {
      if (zoom.fit) zoom.scale = fitScale();
      let at = null;
      if (anchor) {
        const r = frameBox.getBoundingClientRect();
        at = [(anchor[0] - r.left) / r.width, (anchor[1] - r.top) / r.height];
      }
      frameBox.style.width = W * zoom.scale + 'px';
      frameBox.style.height = H * zoom.scale + 'px';
      if (at) {
        const r = frameBox.getBoundingClientRect();
        stage.scrollLeft += r.left + at[0] * r.width - anchor[0];
        stage.scrollTop += r.top + at[1] * r.height - anchor[1];
      }
      $('zoom-label').textContent = (zoom.fit ? 'fit, ' : '') + Math.round(zoom.scale * 100) + ' %';
    }
    function setZoom(z, anchor) {
      if (z === 'fit') {
        zoom.fit = true;
      } else {
        const scale = Number(z);
        if (!Number.isFinite(scale) || scale <= 0) throw new Error('zoom ' + z + ': give fit or a factor such as 2');
        zoom.fit = false;
        zoom.scale = Math.min(64, Math.max(1 / 16, scale));
      }
      applyZoom(anchor);
    }
    $('zoom-fit').onclick = () => setZoom('fit');
    $('zoom-1').onclick = () => setZoom(1);
    $('zoom-in').onclick = () => setZoom(zoom.scale * 1.25);
    $('zoom-out').onclick = () => setZoom(zoom.scale / 1.25);
    stage.addEventListener('wheel', (ev) => {
      ev.preventDefault();
      setZoom(zoom.scale * Math.pow(1.25, -Math.sign(ev.deltaY)), [ev.clientX, ev.clientY]);
    }, { passive: false });
    new ResizeObserver(() => { if (zoom.fit) applyZoom(); }).observe(stage);
    try {
      setZoom(params.get('zoom') || 'fit');
    } catch (e) {
      setZoom('fit');
      status(e.message, true);
    }
    const gl = canvas.getContext('webgl2', { preserveDrawingBuffer: true, antialias: false, alpha: false });
    if (!gl) throw new Error('this browser has no WebGL2');
    if (scene.planes > 64) throw new Error('the page handles at most 64 planes');
    // Programs: the plain shader, and for a frame with light parts a relit shader per set of
    // parts a choice re-weights and a shader of the other parts' sums (relitReady); every
    // uniform the page sets is kept (`uniforms`) and set on each program, those linked later too.
    const uniforms = new Map();
    const programs = [];
    function setOn(entry, fn, name, args) {
      if (!entry.locations.has(name)) entry.locations.set(name, gl.getUniformLocation(entry.program, name));
      const at = entry.locations.get(name);
      if (at !== null) {
        gl.useProgram(entry.program);
        gl[fn](at, ...args);
      }
    }
    function link(fragment) {
      const program = gl.createProgram();
      gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, VERTEX));
      gl.attachShader(program, compile(gl, gl.FRAGMENT_SHADER, fragment));
      gl.linkProgram(program);
      if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(program));
      const entry = { program, locations: new Map() };
      uniforms.forEach(([fn, args], name) => setOn(entry, fn, name, args));
      programs.push(entry);
      return entry;
    }
    function uni(fn, name, ...args) {
      uniforms.set(name, [fn, args]);
      programs.forEach((entry) => setOn(entry, fn, name, args));
    }
    const plain = link(fragmentSource(lutLayout, null));
    gl.bindVertexArray(gl.createVertexArray());
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);

    const transTex = texture(gl, gl.TEXTURE_2D);
    const reflTex = texture(gl, gl.TEXTURE_2D_ARRAY);
    const maskTex = texture(gl, gl.TEXTURE_2D);
    const lutTex = { A: texture(gl, gl.TEXTURE_2D), B: texture(gl, gl.TEXTURE_2D) };
    const shaperTex = texture(gl, gl.TEXTURE_2D);
    const cubeTex = texture(gl, gl.TEXTURE_3D);
    gl.texParameteri(gl.TEXTURE_3D, gl.TEXTURE_WRAP_R, gl.CLAMP_TO_EDGE);
    // Complete from the start (a 1-texel placeholder) until a view's tables replace them.
    gl.texImage3D(gl.TEXTURE_3D, 0, gl.RGB32F, 1, 1, 1, 0, gl.RGB, gl.FLOAT, new Float32Array(3));
    gl.bindTexture(gl.TEXTURE_2D, shaperTex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB32F, 1, 1, 0, gl.RGB, gl.FLOAT, new Float32Array(3));
    // The reflection layers (the planes', then the pane groups') are sized per frame.
    gl.bindTexture(gl.TEXTURE_2D, transTex);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA16F, W, H);
    gl.bindTexture(gl.TEXTURE_2D, maskTex);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, W, H);
    for (const set of ['A', 'B']) {
      gl.bindTexture(gl.TEXTURE_2D, lutTex[set]);
      gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, lutLayout.width, lutLayout.rows_per_slot * slots.length);
    }
    // The light parts' passes and the fixed sums (relitReady): complete from the start (one
    // texel) until a frame with light parts replaces them.
    const [partsTex, fixedTex] = [0, 1].map(() => {
      const t = texture(gl, gl.TEXTURE_2D_ARRAY);
      gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.RGBA32UI, 1, 1, 1, 0, gl.RGBA_INTEGER, gl.UNSIGNED_INT, new Uint32Array(4));
      return t;
    });
    const units = [['uTrans', gl.TEXTURE_2D, transTex], ['uRefl', gl.TEXTURE_2D_ARRAY, reflTex],
      ['uMask', gl.TEXTURE_2D, maskTex], ['uLutA', gl.TEXTURE_2D, lutTex.A], ['uLutB', gl.TEXTURE_2D, lutTex.B],
      ['uShaper', gl.TEXTURE_2D, shaperTex], ['uCube', gl.TEXTURE_3D, cubeTex], ['uParts', gl.TEXTURE_2D_ARRAY, partsTex],
      ['uFixed', gl.TEXTURE_2D_ARRAY, fixedTex]];
    const unitOf = (name) => units.findIndex(([n]) => n === name);
    units.forEach(([name, target, tex], i) => {
      gl.activeTexture(gl.TEXTURE0 + i);
      gl.bindTexture(target, tex);
      uni('uniform1i', name, i);
    });
    // Texture units: one per sampler, then an idle one that uploads bind to.
    gl.activeTexture(gl.TEXTURE0 + units.length);
    // A view's tables, uploaded when it is chosen (index into scene.views; -1: standard).
    const viewTables = {};
    async function setView(i) {
      if (i >= 0 && !viewTables[i]) viewTables[i] = await source.view(i);
      const v = scene.views[i];
      uni('uniform1i', 'uView', v ? 1 : 0);
      if (v) {
        const data = viewTables[i];
        const shaperFloats = v.shaper ? v.shaper.rows * lutLayout.width * 3 : 0;
        uni('uniform1i', 'uHasShaper', v.shaper ? 1 : 0);
        uni('uniform1i', 'uHasCube', v.cube ? 1 : 0);
        if (v.shaper) {
          gl.activeTexture(gl.TEXTURE0 + unitOf('uShaper'));
          gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB32F, lutLayout.width, v.shaper.rows, 0, gl.RGB, gl.FLOAT, data.subarray(0, shaperFloats));
          uni('uniform1i', 'uShaperLen', v.shaper.len);
          uni('uniform3fv', 'uShaperScale', v.shaper.scale);
          uni('uniform3fv', 'uShaperOffset', v.shaper.offset);
        }
        if (v.cube) {
          const n = v.cube.n;
          gl.activeTexture(gl.TEXTURE0 + unitOf('uCube'));
          gl.texImage3D(gl.TEXTURE_3D, 0, gl.RGB32F, n, n, n, 0, gl.RGB, gl.FLOAT, data.subarray(shaperFloats, shaperFloats + n * n * n * 3));
          uni('uniform1i', 'uCubeN', n);
          uni('uniform3fv', 'uCubeScale', v.cube.scale);
          uni('uniform3fv', 'uCubeOffset', v.cube.offset);
        }
        gl.activeTexture(gl.TEXTURE0 + units.length);
      }
      state.view = i;
    }
    uni('uniform1i', 'uHeight', H);
    uni('uniform1i', 'uMode', { code8: 0, cos: 1, normal: 2 }[scene.mask_mode]);
    uni('uniform1i', 'uPlanes', scene.planes);
    uni('uniform1i', 'uConvert', scene.display_matrix ? 1 : 0);
    uni('uniformMatrix3fv', 'uDisplay', true, scene.display_matrix || [1, 0, 0, 0, 1, 0, 0, 0, 1]);

    // Every product's table, on the CPU (a swap then uploads one slot's rows and nothing else).
    const luts = await source.luts(products.length);

    const state = {
      // Slot i is product i's id (scene.slots): each glass starts with its own product.
      sets: { A: slots.map((_, i) => i), B: null },
      ev: Number(params.get('ev') ?? scene.initial_ev ?? 0),
      ab: params.get('ab') || 'A',
      split: Number(params.get('split') ?? 0.5),
      edit: 'A',
      frame: Number(params.get('frame') ?? 0),
      view: -1,
      selected: null,
      data: null,
      drawn: 0,
      lastSwapMs: null,
      lastFrameLoadMs: null,
      lastUnit: null,
      // The unit being put together on the page: panes {glass, flip} and gaps {gap_mm, gas}.
      unit: [],
      // Exposure in stops per light part (light mixing), by group name.
      partEv: {},
    };
    const applySpec = (set, spec) => {
      for (const [id, p] of parseChoices(products, slots, spec)) state.sets[set][slots.indexOf(id)] = p;
    };
    try {
      applySpec('A', params.get('glass') ?? scene.initial_glass ?? '');
      state.sets.B = state.sets.A.slice();
      applySpec('B', params.get('glassB') ?? '');
    } catch (e) {
      state.sets.B = state.sets.B || state.sets.A.slice();
      status(e.message, true);
    }
    if (!Number.isFinite(state.ev)) state.ev = 0;

    function uploadSlot(set, slot) {
      gl.bindTexture(gl.TEXTURE_2D, lutTex[set]);
      gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, slot * lutLayout.rows_per_slot, lutLayout.width,
        lutLayout.rows_per_slot, gl.RGBA, gl.FLOAT, luts[state.sets[set][slot]]);
    }

    function draw() {
      uni('uniform1f', 'uGain', Math.pow(2, state.ev));
      uni('uniform1i', 'uAB', { A: 0, B: 1, split: 2 }[state.ab] ?? 0);
      uni('uniform1f', 'uSplitX', state.split * W);
      const program = state.data && state.data.info.parts.length ? relitReady() : plain;
      gl.viewport(0, 0, W, H);
      gl.useProgram(program.program);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      placeSplitLine();
      state.drawn += 1;
      canvas.dataset.drawn = String(state.drawn);
      window.glassdbFrameDrawn = state.drawn;
    }

    // The split line over the frame, where the shader switches from set A to set B.
    const splitLine = $('split-line');
    function placeSplitLine() {
      splitLine.hidden = state.ab !== 'split';
      splitLine.style.left = (100 * Math.min(1, Math.max(0, state.split))) + '%';
    }
    splitLine.addEventListener('pointerdown', (ev) => {
      ev.preventDefault();
      splitLine.setPointerCapture(ev.pointerId);
      splitLine.dataset.dragging = '1';
    });
    splitLine.addEventListener('pointermove', (ev) => {
      if (!splitLine.dataset.dragging) return;
      const r = frameBox.getBoundingClientRect();
      state.split = Math.min(1, Math.max(0, (ev.clientX - r.left) / r.width));
      $('split').value = String(state.split);
      draw();
    });
    const stopDrag = () => { delete splitLine.dataset.dragging; };
    splitLine.addEventListener('pointerup', stopDrag);
    splitLine.addEventListener('pointercancel', stopDrag);

    // Waits for the frame drawn (reading a pixel back finishes the drawing): only where a time
    // is taken, so that the exposure slider and the split drag do not stall on the GPU.
    function finish() {
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    }

    async function loadFrame(i) {
      const t0 = performance.now();
      const data = await source.frame(i);
      gl.bindTexture(gl.TEXTURE_2D, transTex);
      gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, W, H, gl.RGBA, gl.HALF_FLOAT, data.passes.subarray(0, W * H * 4));
      const groups = data.info.groups;
      gl.bindTexture(gl.TEXTURE_2D_ARRAY, reflTex);
      gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.RGBA16F, W, H, scene.planes + groups.length, 0, gl.RGBA, gl.HALF_FLOAT,
        data.passes.subarray(W * H * 4));
      // Each plane's pane groups 1 and 2 (deeper ones: their shares are in group 2's).
      const layers = new Int32Array(64 * 2).fill(-1);
      groups.forEach((g, j) => {
        if (g.plane < 64 && g.group >= 1 && g.group <= 2) layers[g.plane * 2 + g.group - 1] = scene.planes + j;
      });
      uni('uniform2iv', 'uGroupLayer', layers);
      if (data.info.groupsFolded) status('frame ' + i + ': ' + data.info.groupsFolded, false);
      gl.bindTexture(gl.TEXTURE_2D, maskTex);
      gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, W, H, gl.RGBA, gl.FLOAT, data.mask);
      // The side of each plane the camera sees in this frame (it may change as the camera moves).
      uni('uniform1iv', 'uSide', Int32Array.from({ length: 64 }, (_, k) => data.info.plane_sides[k] === 'back' ? 1 : 0));
      if (data.info.parts.length > 16) throw new Error('frame ' + i + ': ' + data.info.parts.length + ' light parts; the page shows at most 16');
      if (data.info.parts.length) {
        // Per part: its transmission and each pixel's plane's reflection, then its pane groups'.
        const per = groups.length ? 2 : 1;
        gl.bindTexture(gl.TEXTURE_2D_ARRAY, partsTex);
        gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.RGBA32UI, W, H, data.info.parts.length * per, 0, gl.RGBA_INTEGER,
          gl.UNSIGNED_INT, data.parts);
        gl.bindTexture(gl.TEXTURE_2D_ARRAY, fixedTex);
        gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.RGBA32UI, W, H, 2 * fixedLayers(per) + 2, 0, gl.RGBA_INTEGER,
          gl.UNSIGNED_INT, null);
      }
      state.frame = i;
      state.data = data;
      relit.fixedKey = null;
      renderPartSliders();
      renderGlasses();
      draw();
      finish();
      state.lastFrameLoadMs = performance.now() - t0;
    }

    // ---- the relit swap: a factor per light part and set (docs/viewer.md, "Relit swap") ----

    // t of product table `lut` seen from `side` at cos θ, as compose's GlassSideLut::at_cos.
    function tAtCos(lut, side, cos) {
      const row = (side * 2 + 1) * lutLayout.rows_per_curve * lutLayout.width * 4;
      const xf = Math.min(1, Math.max(0, cos)) * lutLayout.fine_steps;
      const k = Math.min(Math.floor(xf), lutLayout.fine_steps - 1), fr = xf - k;
      const at = (e) => { const b = row + (lutLayout.fine_offset + e) * 4; return [lut[b], lut[b + 1], lut[b + 2]]; };
      const lo = at(k), hi = at(k + 1);
      return lo.map((v, c) => v + (hi[c] - v) * fr);
    }

    // Part `part`'s factor in set `set`: 1 through no glazing, t(θ_sun) or t_dif of the product
    // chosen for its aperture's glass, times 2^(its exposure).
    function partFactor(part, set) {
      let f = [1, 1, 1];
      if (part.kind !== 'unglazed') {
        const slot = slots.indexOf(part.id);
        const p = slot >= 0 ? state.sets[set][slot] : -1;
        if (p < 0 || !products[p]) f = part.factor;
        else if (part.kind === 'diffuse') f = products[p].t_dif;
        else f = tAtCos(luts[p], part.side === 'back' ? 1 : 0, part.cos_theta);
      }
      const gain = Math.pow(2, state.partEv[part.group] || 0);
      return f.map((v) => v * gain);
    }

    // The relit swap (docs/viewer.md, "Relit swap"): a choice for glass id `active` changes the
    // factors of that id's parts only, so the other parts are summed once into the fixed layers
    // (per set, with their factors; drawn again when those change: another active id, a part's
    // exposure, another frame), and the frame is drawn from those sums and the active parts.
    const relit = { active: null, fixedKey: null, fixedDraws: 0, programs: new Map(), fixed: new Map(), framebuffer: gl.createFramebuffer() };
    const cached = (map, key, source) => {
      if (!map.has(key)) map.set(key, link(source()));
      return map.get(key);
    };

    // The program to draw the frame with, its active parts' factors set, the fixed sums drawn.
    function relitReady() {
      const parts = state.data.info.parts;
      const layers = state.data.info.groups.length ? 2 : 1;
      const id = relit.active ?? state.selected ?? Number(Object.keys(state.data.info.ids)[0]);
      const all = parts.map((_, i) => i);
      const active = all.filter((i) => parts[i].kind !== 'unglazed' && parts[i].id === id);
      const rest = all.filter((i) => !active.includes(i));
      const factors = { A: parts.map((p) => partFactor(p, 'A')), B: parts.map((p) => partFactor(p, 'B')) };
      const program = cached(relit.programs, layers + ':' + active, () => fragmentSource(lutLayout, { active, layers }));
      for (const set of ['A', 'B']) {
        if (active.length) setOn(program, 'uniform3fv', 'uFactor' + set, [active.flatMap((i) => factors[set][i])]);
      }
      const key = JSON.stringify([state.frame, layers, rest, rest.map((i) => [factors.A[i], factors.B[i]])]);
      if (key !== relit.fixedKey) {
        drawFixed(rest, layers, factors, gathers({ active, layers }) ? active : null);
        relit.fixedKey = key;
      }
      return program;
    }

    // Makes glass `id` the active one (its glass clicked in the list): the fixed sums are drawn
    // now, so that the choice of a product for it draws only the frame.
    function prepareActive(id) {
      relit.active = id;
      if (state.data && state.data.info.parts.length) relitReady();
    }

    // The fixed sums of parts `rest` for both sets into fixedTex (fixedSource).
    function drawFixed(rest, layers, factors, gather) {
      const program = cached(relit.fixed, layers + ':' + rest + ':' + gather, () => fixedSource(rest, layers, gather));
      const per = fixedLayers(layers);
      const targets = Array.from({ length: per + (gather ? 2 : 0) }, (_, k) => gl.COLOR_ATTACHMENT0 + k);
      gl.bindFramebuffer(gl.FRAMEBUFFER, relit.framebuffer);
      gl.viewport(0, 0, W, H);
      ['A', 'B'].forEach((set, s) => {
        targets.forEach((t, k) => gl.framebufferTextureLayer(gl.FRAMEBUFFER, t, fixedTex, 0, k < per ? s * per + k : per + k));
        gl.drawBuffers(targets);
        if (rest.length) setOn(program, 'uniform3fv', 'uFactor', [rest.flatMap((i) => factors[set][i])]);
        gl.useProgram(program.program);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
      });
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      relit.fixedDraws += 1;
    }

    // One exposure slider per light part (light mixing), beside the frame.
    function renderPartSliders() {
      const box = $('light-parts');
      const parts = state.data ? state.data.info.parts : [];
      box.parentElement.hidden = !parts.length;
      box.replaceChildren(...parts.map((part) => {
        const row = document.createElement('label');
        row.className = 'light-part';
        const through = part.kind === 'unglazed' ? '' : ' through id ' + part.id;
        const input = document.createElement('input');
        Object.assign(input, { type: 'range', min: -6, max: 6, step: 0.1, value: state.partEv[part.group] || 0 });
        input.dataset.group = part.group;
        const value = document.createElement('span');
        const say = () => { value.textContent = Number(input.value).toFixed(1) + ' EV'; };
        say();
        input.oninput = () => { state.partEv[part.group] = Number(input.value); say(); draw(); };
        row.append(part.group + ' (' + part.source + through + ') ', input, ' ', value);
        return row;
      }));
    }

    // Chooses product `p` for glass `id` in set `set` (default: the edited one) and draws.
    function choose(id, p, set) {
      set = set || state.edit;
      const t0 = performance.now();
      const slot = slots.indexOf(id);
      if (slot < 0 || !luts[p]) throw new Error('no glass ' + id + ' or product ' + p);
      state.sets[set][slot] = p;
      relit.active = id;
      uploadSlot(set, slot);
      draw();
      finish();
      state.lastSwapMs = performance.now() - t0;
      renderGlasses();
      renderProducts();
      return state.lastSwapMs;
    }

    // ---- the page's lists ----

    function swatch(rgb) {
      let c = rgb;
      if (scene.display_matrix) {
        const m = scene.display_matrix;
        c = [0, 1, 2].map((r) => m[3 * r] * rgb[0] + m[3 * r + 1] * rgb[1] + m[3 * r + 2] * rgb[2]);
      }
      const s = document.createElement('span');
      s.className = 'swatch';
      s.style.background = 'rgb(' + c.map((v) => Math.round(255 * srgbEncode(v))).join(',') + ')';
      return s;
    }

    function productValues(p) {
      const f = (v) => v.toFixed(3);
      const l = p.luminous;
      const luminous = !l ? 'no luminous values'
        : p.unit ? 'Tv ' + f(l.transmittance) + ' Rv out ' + f(l.reflectance) + ' Rv in ' + f(l.reflectance_back)
          : 'τv ' + f(l.transmittance) + ' ρv ' + f(l.reflectance);
      return luminous + ' · t0 ' + p.t0.map(f).join('/') + ' · r0 ' + p.r0.map(f).join('/');
    }

    // A unit's build-up, outside first: panes (thickness, product, coated surfaces) and gaps.
    function buildupText(unit) {
      const mm = (v) => (Math.round(v * 10) / 10) + ' mm';
      return unit.elements.map((e) => e.kind === 'gap' ? mm(e.thickness_mm) + ' ' + e.gas
        : (e.thickness_mm ? mm(e.thickness_mm) + ' ' : '') + e.name
          + (e.coated_surfaces.length ? ' (coating on #' + e.coated_surfaces.join(', #') + ')' : '')
          + (e.flipped ? ' [flipped]' : '')).join(' | ')
        + (unit.thickness_mm ? ' · ' + mm(unit.thickness_mm) + ' in all' : '');
    }

    function renderGlasses() {
      const ul = $('glasses');
      ul.textContent = '';
      const ids = state.data ? Object.keys(state.data.info.ids).map(Number) : [];
      for (const id of ids) {
        const slot = slots.indexOf(id);
        const li = document.createElement('li');
        li.dataset.id = String(id);
        if (state.selected === id) li.className = 'selected';
        const a = products[state.sets.A[slot]], b = products[state.sets.B[slot]];
        li.append(swatch(a.t0));
        const name = document.createElement('span');
        name.className = 'name';
        name.textContent = 'id ' + id + ': A ' + a.name + (a !== b ? ' | B ' + b.name : '');
        li.title = name.textContent;
        li.append(name);
        const px = document.createElement('span');
        px.className = 'values';
        px.textContent = state.data.info.ids[id] + ' px';
        li.append(px);
        li.onclick = () => { state.selected = id; prepareActive(id); renderGlasses(); renderProducts(); };
        ul.append(li);
      }
    }

    function renderProducts() {
      const ul = $('products');
      ul.textContent = '';
      const q = $('search').value.trim().toLowerCase();
      const slot = slots.indexOf(state.selected);
      for (const p of products) {
        if (q && !p.name.toLowerCase().includes(q) && String(p.id) !== q) continue;
        const li = document.createElement('li');
        li.dataset.index = String(p.index);
        if (slot >= 0 && state.sets[state.edit][slot] === p.index) li.className = 'current';
        li.append(swatch(p.r0), swatch(p.t0));
        const name = document.createElement('span');
        name.className = 'name';
        name.textContent = p.name;
        const values = document.createElement('div');
        values.className = 'values';
        values.textContent = productValues(p);
        name.append(values);
        let tip = p.name + '\n' + values.textContent;
        if (p.unit) {
          const buildup = document.createElement('div');
          buildup.className = 'buildup';
          buildup.textContent = buildupText(p.unit);
          name.append(buildup);
          tip += '\n' + buildup.textContent;
        }
        li.title = tip + '\n' + (p.request ? 'built on this page' : 'registry id ' + p.id) + ', angle model ' + p.angle_model;
        li.append(name);
        li.onclick = () => {
          if (state.selected === null) { status('click a glass first', true); return; }
          choose(state.selected, p.index);
          status('id ' + state.selected + ' → ' + p.name + ' (' + state.lastSwapMs.toFixed(1) + ' ms)');
        };
        ul.append(li);
      }
    }

    // ---- the probe: the same numbers on the CPU ----

    function probe(x, y) {
      const d = state.data;
      if (!d || x < 0 || y < 0 || x >= W || y >= H) return;
      const i = y * W + x;
      const px = (base) => [0, 1, 2, 3].map((c) => halfToFloat(d.passes[base + 4 * i + c]));
      const tr = px(0);
      const m = d.mask.subarray(4 * i, 4 * i + 4);
      const f = (v) => v.toPrecision(4);
      let text = 'pixel (' + x + ', ' + y + ')\ntransmission ' + tr.slice(0, 3).map(f).join(' ') + '  alpha ' + f(tr[3]);
      const slot = Math.round(m[0]) - 1;
      if (slot < 0) {
        $('probe').textContent = text + '\nno glass';
        return;
      }
      const plane = Math.round(m[1]);
      const side = d.info.plane_sides[plane] === 'back' ? 1 : 0;
      const cos = scene.mask_mode === 'code8' ? m[2] / 255 : scene.mask_mode === 'cos' ? m[2] : 1;
      const set = state.ab === 'B' || (state.ab === 'split' && x >= state.split * W) ? 'B' : 'A';
      const lut = luts[state.sets[set][slot]];
      const at = (term, e) => {
        const base = (side * 2 + term) * lutLayout.rows_per_curve * lutLayout.width * 4 + e * 4;
        return [lut[base], lut[base + 1], lut[base + 2]];
      };
      let r, t;
      if (scene.mask_mode === 'code8') {
        r = at(0, Math.round(m[2])); t = at(1, Math.round(m[2]));
      } else if (scene.mask_mode === 'cos') {
        const xf = Math.min(1, Math.max(0, m[2])) * lutLayout.fine_steps;
        const k = Math.min(Math.floor(xf), lutLayout.fine_steps - 1), fr = xf - k;
        const lerp = (term) => at(term, lutLayout.fine_offset + k).map((v, c) => v + (at(term, lutLayout.fine_offset + k + 1)[c] - v) * fr);
        r = lerp(0); t = lerp(1);
      } else {
        r = at(0, lutLayout.normal_offset); t = at(1, lutLayout.normal_offset);
      }
      const rf = px(W * H * 4 * (1 + plane)).slice(0, 3);
      const k = m[3];
      const out = [0, 1, 2].map((c) => tr[c] * (1 - k + k * t[c]) + rf[c] * r[c] * k);
      text += '\nid ' + slots[slot] + ' (' + products[state.sets[set][slot]].name + ', set ' + set + ')' +
        '\nplane ' + plane + ' (' + (side ? 'back' : 'front') + ')' +
        '\nθ ' + (Math.acos(Math.min(1, Math.max(-1, cos))) * 180 / Math.PI).toFixed(2) + '°  cos θ ' + cos.toFixed(4) +
        (k !== 1 ? '  coverage ' + f(k) : '') +
        '\nr ' + r.map(f).join(' ') + '\nt ' + t.map(f).join(' ') +
        '\nreflection ' + rf.map(f).join(' ') + '\ncomposite (linear) ' + out.map(f).join(' ');
      $('probe').textContent = text;
    }

    function canvasPixel(ev) {
      const rect = canvas.getBoundingClientRect();
      return [Math.floor((ev.clientX - rect.left) * W / rect.width), Math.floor((ev.clientY - rect.top) * H / rect.height)];
    }
    canvas.addEventListener('mousemove', (ev) => probe(...canvasPixel(ev)));
    canvas.addEventListener('click', (ev) => probe(...canvasPixel(ev)));

    // ---- controls ----

    const frameInput = $('frame');
    frameInput.max = String(scene.frames.length - 1);
    frameInput.disabled = scene.frames.length < 2;
    const frameLabel = () => { $('frame-label').textContent = scene.frames[state.frame]; };
    frameInput.oninput = async () => {
      try {
        await loadFrame(Number(frameInput.value));
        frameLabel();
      } catch (e) { status(e.message, true); }
    };
    const viewSelect = $('view');
    scene.views.forEach((v, i) => {
      const o = document.createElement('option');
      o.value = String(i);
      o.textContent = v.name + (v.title ? ' (' + v.title + ')' : '');
      viewSelect.append(o);
    });
    viewSelect.value = 'standard';
    viewSelect.onchange = async () => {
      try {
        await setView(viewSelect.value === 'standard' ? -1 : Number(viewSelect.value));
        draw();
      } catch (e) { status(e.message, true); }
    };
    const wantView = params.get('view');
    if (wantView && wantView !== 'standard') {
      const i = scene.views.findIndex((v) => v.name === wantView);
      if (i < 0) status('no view named "' + wantView + '"', true);
      else { await setView(i); viewSelect.value = String(i); }
    } else {
      await setView(-1);
    }
    const evInput = $('ev');
    evInput.value = String(state.ev);
    $('ev-label').textContent = state.ev.toFixed(1);
    evInput.oninput = () => { state.ev = Number(evInput.value); $('ev-label').textContent = state.ev.toFixed(1); draw(); };
    for (const r of document.querySelectorAll('input[name=ab]')) {
      r.checked = r.value === state.ab;
      r.onchange = () => { state.ab = r.value; draw(); };
    }
    $('split').value = String(state.split);
    $('split').oninput = () => { state.split = Number($('split').value); draw(); };
    for (const r of document.querySelectorAll('input[name=edit]')) {
      r.onchange = () => { state.edit = r.value; renderProducts(); };
    }
    $('copy-ab').onclick = () => {
      const other = state.edit === 'A' ? 'B' : 'A';
      state.sets[other] = state.sets[state.edit].slice();
      slots.forEach((_, s) => uploadSlot(other, s));
      draw();
      renderGlasses();
    };
    $('search').oninput = renderProducts;
    const choicesParam = (set) => slots
      .map((id, s) => [id, state.sets[set][s]])
      .filter(([id, p]) => state.data && state.data.info.ids[id] !== undefined)
      .map(([id, p]) => id + ':' + products[p].name).join(',');
    const exportButton = $('export');
    exportButton.disabled = !scene.export_available;
    exportButton.title = scene.export_available ? 'write the self-contained folder with the current products'
      : (EXPORT ? 'this is an exported page' : 'start glassdb view with --export-dir DIR to enable');
    // A request that changes something carries the page's session token (the server refuses
    // it otherwise: crates/view/src/server.rs).
    const session = document.querySelector('meta[name="glassdb-session"]');
    const sessionFetch = (url, init) => fetch(url, { ...init, headers: { 'X-Glassdb-Session': session ? session.content : '' } });
    exportButton.onclick = async () => {
      try {
        // The units built on this page that the edited set uses travel with the request: the
        // server builds them again for the export (it keeps none).
        const used = new Set(slots.map((_, s) => state.sets[state.edit][s]));
        const units = products.filter((p) => p.request && used.has(p.index)).map((p) => ({ elements: p.request }));
        const r = await sessionFetch('api/export', { method: 'POST', body: JSON.stringify({ glass: choicesParam(state.edit), ev: state.ev, units }) });
        const body = await r.json();
        if (!r.ok) throw new Error(body.error);
        status('exported to ' + body.path + ' (' + body.files + ' files, ' + (body.bytes / 1e6).toFixed(2) + ' MB)');
      } catch (e) { status('export failed: ' + e.message, true); }
    };

    // ---- a unit built on the page: the server runs the stack engine and sends its table ----

    const unitStatus = (text, isError) => {
      const s = $('unit-status');
      s.textContent = text;
      s.className = isError ? 'error' : '';
    };
    const layers = scene.unit_layers;
    const canBuild = !EXPORT && layers.length > 0;
    state.unit = layers.length ? [{ glass: layers[0].id, flip: false }, { gap_mm: 12.7, gas: 'argon' }, { glass: layers[0].id, flip: false }] : [];
    function renderUnitBuilder() {
      const ol = $('unit-elements');
      ol.textContent = '';
      const panes = state.unit.filter((e) => e.glass !== undefined).length;
      let pane = 0;
      state.unit.forEach((e, k) => {
        const li = document.createElement('li');
        if (e.glass !== undefined) {
          pane += 1;
          li.append(pane === 1 ? 'outer pane ' : pane === panes ? 'inner pane ' : 'pane ' + pane + ' ');
          const sel = document.createElement('select');
          sel.className = 'unit-glass';
          for (const l of layers) {
            const o = document.createElement('option');
            o.value = String(l.id);
            o.textContent = l.name;
            sel.append(o);
          }
          sel.value = String(e.glass);
          sel.title = 'the catalog glass of this pane';
          sel.onchange = () => { e.glass = Number(sel.value); };
          const flip = document.createElement('input');
          flip.type = 'checkbox';
          flip.className = 'unit-flip';
          flip.checked = e.flip;
          flip.onchange = () => { e.flip = flip.checked; };
          const label = document.createElement('label');
          label.title = 'turn the pane round: its coating on the other surface';
          label.append(flip, ' flip');
          li.append(sel, ' ', label);
        } else {
          li.append('gap ');
          const width = document.createElement('input');
          width.type = 'number';
          width.className = 'unit-gap';
          width.min = '0';
          width.step = '0.1';
          width.value = String(e.gap_mm);
          // An empty or malformed box is NaN (sent as null, refused by the server, which says why).
          width.oninput = width.onchange = () => { e.gap_mm = width.value.trim() === '' ? NaN : Number(width.value); };
          const gas = document.createElement('select');
          gas.className = 'unit-gas';
          for (const g of scene.gases) {
            const o = document.createElement('option');
            o.value = g;
            o.textContent = g;
            gas.append(o);
          }
          if (e.gas === undefined) e.gas = 'air';
          gas.value = e.gas;
          gas.onchange = () => { e.gas = gas.value; };
          li.append(width, ' mm ', gas);
          if (panes > 2 && k === state.unit.length - 2) {
            const remove = document.createElement('button');
            remove.type = 'button';
            remove.textContent = 'remove gap and pane';
            remove.onclick = () => { state.unit.splice(k, 2); renderUnitBuilder(); };
            li.append(' ', remove);
          }
        }
        ol.append(li);
      });
      $('unit-add-pane').disabled = !canBuild;
      $('unit-build').disabled = !canBuild;
      if (!canBuild) {
        unitStatus(EXPORT ? 'an exported page builds no units (it has no server); its units are those exported'
          : 'start glassdb view with --catalog CATALOG to build units from its glasses');
      }
    }
    $('unit-add-pane').onclick = () => {
      state.unit.push({ gap_mm: 12.7, gas: 'argon' }, { glass: layers[0].id, flip: false });
      renderUnitBuilder();
    };
    // Builds the unit on the builder (NaN widths travel as null and are refused by the server,
    // which says why), puts it on the selected glass and draws: the milliseconds from the request
    // to the frame on screen, and the server's share.
    async function buildUnit() {
      const t0 = performance.now();
      if (state.selected === null) throw new Error('click a glass first');
      const elements = state.unit.map((e) => ({ ...e }));
      const key = JSON.stringify(elements);
      let p = products.find((q) => q.request && JSON.stringify(q.request) === key);
      let buildMs = 0;
      if (!p) {
        const r = await sessionFetch('api/unit', { method: 'POST', body: JSON.stringify({ elements }) });
        let body;
        try { body = await r.json(); } catch (e) { throw new Error(r.status + ' ' + r.statusText); }
        if (!r.ok) throw new Error(body.error || r.status + ' ' + r.statusText);
        const built = readBuiltUnit(body);
        p = built.product;
        p.index = products.length;
        p.request = elements;
        products.push(p);
        luts.push(built.lut);
        buildMs = built.buildMs;
      }
      choose(state.selected, p.index);
      state.lastUnit = { ms: performance.now() - t0, buildMs, name: p.name };
      return state.lastUnit;
    }
    // Builds and says the outcome under the builder (the button and the hook alike).
    async function buildAndSay() {
      unitStatus('building…');
      try {
        const u = await buildUnit();
        unitStatus('id ' + state.selected + ' → ' + u.name + '\non screen in ' + u.ms.toFixed(0) + ' ms (server ' + u.buildMs.toFixed(0) + ' ms)');
        return u;
      } catch (e) {
        unitStatus('cannot build the unit: ' + e.message, true);
        throw e;
      }
    }
    $('unit-build').onclick = async () => {
      // What the controls show (a box cleared without an input event included).
      for (const box of document.querySelectorAll('#unit-elements input.unit-gap')) box.onchange();
      try { await buildAndSay(); } catch (e) { /* said under the builder */ }
    };
    renderUnitBuilder();

    // ---- automation hooks ----
    window.glassdb = {
      scene,
      choose: (id, product, set) => choose(id, typeof product === 'number' ? product : findProduct(products, product), set),
      setEv: (ev) => { state.ev = ev; draw(); },
      // A light part's exposure in stops (its slider), by group name.
      setPartEv: (group, ev) => { state.partEv[group] = ev; renderPartSliders(); draw(); },
      // The relit swap's active glass id and how often the other parts' sums were drawn.
      relitStats: () => ({ active: relit.active, fixedDraws: relit.fixedDraws }),
      // Each light part's factor per set (none: passes without a light-path split).
      partFactors: () => (state.data ? state.data.info.parts : []).map((p) => ({ group: p.group, A: partFactor(p, 'A'), B: partFactor(p, 'B') })),
      setView: async (name) => { await setView(scene.views.findIndex((v) => v.name === name)); draw(); },
      setAB: (mode, split) => { state.ab = mode; if (split !== undefined) state.split = split; draw(); },
      // Where the split line stands (0–1 across the frame) while A | B is split, else null.
      split: () => (state.ab === 'split' ? state.split : null),
      setZoom: (z) => setZoom(z),
      // The frame's scale on screen (screen pixels per frame pixel) and whether it fits the stage.
      zoom: () => ({ fit: zoom.fit, scale: zoom.scale }),
      // Puts `elements` on the unit builder and builds it (as its button does).
      buildUnit: async (elements) => { state.unit = elements.map((e) => ({ ...e })); renderUnitBuilder(); return buildAndSay(); },
      lastUnit: () => state.lastUnit,
      loadFrame,
      products: () => ({ A: Object.fromEntries(slots.map((id, s) => [id, products[state.sets.A[s]].name])),
        B: Object.fromEntries(slots.map((id, s) => [id, products[state.sets.B[s]].name])) }),
      lastSwapMs: () => state.lastSwapMs,
      lastFrameLoadMs: () => state.lastFrameLoadMs,
      // The canvas's RGBA bytes, rows top to bottom, in base64.
      readPixels: () => {
        const px = new Uint8Array(W * H * 4);
        gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE, px);
        const flipped = new Uint8Array(W * H * 4);
        for (let y = 0; y < H; y++) flipped.set(px.subarray((H - 1 - y) * W * 4, (H - y) * W * 4), y * W * 4);
        let bin = '';
        for (let i = 0; i < flipped.length; i += 0x8000) bin += String.fromCharCode.apply(null, flipped.subarray(i, i + 0x8000));
        return btoa(bin);
      },
    };
    window.glassdbProducts = window.glassdb.products;

    for (const set of ['A', 'B']) slots.forEach((_, s) => uploadSlot(set, s));
    state.frame = Math.min(Math.max(0, Math.floor(state.frame) || 0), scene.frames.length - 1);
    frameInput.value = String(state.frame);
    await loadFrame(state.frame);
    frameLabel();
    const first = state.data ? Object.keys(state.data.info.ids).map(Number)[0] : undefined;
    if (state.selected === null && first !== undefined) { state.selected = first; prepareActive(first); renderGlasses(); }
    renderProducts();
    if (!errors.length) status('ready: ' + W + '×' + H + ', ' + scene.planes + ' plane(s), ' + products.length + ' products');
    // Milliseconds from the start of navigation to the first frame drawn and the page ready.
    window.glassdbReadyMs = performance.now();
    window.glassdbReady = true;
  }

  main().catch((e) => { status(String(e.message || e), true); window.glassdbReady = true; });
})();

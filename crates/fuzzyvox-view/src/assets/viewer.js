// fuzzyvox map viewer.
//
// Draws the voxels of a fuzzyvox map (window.FUZZYVOX_DATA, written into the page by
// `fuzzyvox view`) as cubes with WebGL2: one texture holds the 16-byte voxel records exactly
// as the Rust side wrote them, and each visible class is one draw call.
// Frames are drawn on demand only (after input, a resize or a change of options).
//
// This file is inlined into viewer.html, so it must never contain the closing tag of a script
// element. World axes: x east, y north, z up, in metres.
"use strict";

(() => {
  // ------------------------------------------------------------------ error accounting
  // Tests read body[data-errors] and body[data-status]; every console.error, uncaught error
  // and unhandled rejection counts.
  const body = document.body;
  let errorCount = 0;
  body.dataset.errors = "0";
  function countError() {
    errorCount += 1;
    body.dataset.errors = String(errorCount);
  }
  const consoleError = console.error.bind(console);
  console.error = (...args) => {
    countError();
    consoleError(...args);
  };
  window.addEventListener("error", countError);
  window.addEventListener("unhandledrejection", countError);

  /** Shows a big red message in the page and marks the page as failed. */
  function fail(reason) {
    body.dataset.status = "error";
    const box = document.getElementById("error");
    if (box) {
      box.textContent = "fuzzyvox viewer: " + reason;
      box.style.display = "block";
    }
    console.error("fuzzyvox-view error: " + reason);
  }

  // ------------------------------------------------------------------ constants
  const CLASS_NAMES = ["occupied", "free", "ambiguous", "unknown"];
  // Size of the drawn voxel relative to the voxel edge: free and unknown voxels are small so
  // they do not hide the obstacles, and are drawn as round dots (one point each) rather than
  // cubes, which keeps hundreds of thousands of them cheap to draw.
  const CLASS_SCALE = [1.0, 0.3, 1.0, 0.3];
  const CLASS_AS_POINTS = [false, true, false, true];
  // Colour modes, in the order of the shader's uMode values.
  const COLOR_MODES = [
    { id: "class", label: "class" },
    { id: "height", label: "height (z)" },
    { id: "occupied", label: "occupied membership" },
    { id: "free", label: "free membership" },
    { id: "ambiguity", label: "ambiguity" },
    { id: "safety", label: "safety" },
  ];
  // Matplotlib's viridis colour map sampled at evenly spaced stops (sRGB, 0-255). Both the
  // shader and the legend interpolate linearly between these stops.
  // The stops are written in by the Rust side from fuzzyvox::figure::palette::VIRIDIS, the
  // figures' own table.
  const VIRIDIS = [/*FUZZYVOX_VIRIDIS*/];
  // Path colours (sRGB, 0-255), written in from fuzzyvox::figure::palette like the stops
  // above: trajectories, flights clear of the true scene, flights that meet it, and others.
  const PATH_RGB = {/*FUZZYVOX_PATH_COLORS*/};
  const PATH_COLORS = Object.fromEntries(
    Object.entries(PATH_RGB).map(([kind, rgb]) => [kind, [...rgb.map((c) => c / 255), 1]]));
  const BACKGROUND = [0xf4 / 255, 0xf4 / 255, 0xf0 / 255];
  const FOV_Y = (45 * Math.PI) / 180;
  const RECORD_BYTES = 16;

  /** Viridis colour of t in [0, 1], as [r, g, b] in 0-255. */
  function viridis(t) {
    const x = Math.min(1, Math.max(0, t)) * (VIRIDIS.length - 1);
    const i = Math.min(Math.floor(x), VIRIDIS.length - 2);
    const f = x - i;
    return VIRIDIS[i].map((c, k) => Math.round(c + (VIRIDIS[i + 1][k] - c) * f));
  }

  // ------------------------------------------------------------------ small helpers
  const $ = (id) => document.getElementById(id);

  function el(tag, props = {}, children = []) {
    const node = document.createElement(tag);
    Object.assign(node, props);
    for (const child of children) node.append(child);
    return node;
  }

  /** Largest of 1, 2 or 5 times a power of ten that is not above v. */
  function niceFloor(v) {
    const p = Math.pow(10, Math.floor(Math.log10(v)));
    const f = v / p;
    return (f >= 5 ? 5 : f >= 2 ? 2 : 1) * p;
  }

  /** A length in metres for people: "2 m", "20 cm", "5 mm". */
  function formatLength(m) {
    const a = Math.abs(m);
    if (a >= 1) return `${+m.toPrecision(3)} m`;
    if (a >= 0.01) return `${+(m * 100).toPrecision(3)} cm`;
    return `${+(m * 1000).toPrecision(3)} mm`;
  }

  const formatCount = (n) => n.toLocaleString("en-US");

  // 4×4 matrices, column-major Float32Arrays as WebGL expects.
  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2);
    const m = new Float32Array(16);
    m[0] = f / aspect;
    m[5] = f;
    m[10] = (far + near) / (near - far);
    m[11] = -1;
    m[14] = (2 * far * near) / (near - far);
    return m;
  }

  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const normalize = (a) => {
    const l = Math.hypot(a[0], a[1], a[2]) || 1;
    return [a[0] / l, a[1] / l, a[2] / l];
  };

  function lookAt(eye, target, up) {
    const z = normalize(sub(eye, target));
    const x = normalize(cross(up, z));
    const y = cross(z, x);
    return new Float32Array([
      x[0], y[0], z[0], 0,
      x[1], y[1], z[1], 0,
      x[2], y[2], z[2], 0,
      -dot(x, eye), -dot(y, eye), -dot(z, eye), 1,
    ]);
  }

  function multiply(a, b) {
    const m = new Float32Array(16);
    for (let c = 0; c < 4; c++) {
      for (let r = 0; r < 4; r++) {
        let s = 0;
        for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
        m[c * 4 + r] = s;
      }
    }
    return m;
  }

  /** Projects a point (relative to the scene anchor) to CSS pixels; null when behind the camera. */
  function toScreen(m, p, width, height) {
    const x = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
    const y = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
    const w = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
    if (w <= 1e-9) return null;
    return [(x / w * 0.5 + 0.5) * width, (0.5 - y / w * 0.5) * height];
  }

  // ------------------------------------------------------------------ map data
  function decodeBase64(text) {
    if (!text) return new Uint8Array(0);
    if (typeof Uint8Array.fromBase64 === "function") return Uint8Array.fromBase64(text);
    const bin = atob(text);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    return bytes;
  }

  /** Reads FUZZYVOX_DATA into the form the viewer uses, checking what it relies on. */
  function loadMap(data) {
    if (!data || typeof data !== "object") throw new Error("this page holds no map data");
    const resolution = Number(data.resolution);
    if (!(resolution > 0)) throw new Error("the map resolution is missing or not positive");
    const origin = Array.isArray(data.origin) ? data.origin.map(Number) : [0, 0, 0];
    const byName = new Map((data.classes || []).map((c) => [c.name, c]));
    const classes = CLASS_NAMES.map((name, i) => {
      const c = byName.get(name) || {};
      return {
        name,
        index: i,
        color: Array.isArray(c.color) ? c.color : [128, 128, 128],
        start: c.start | 0,
        count: c.count | 0,
        total: c.total === undefined ? c.count | 0 : Number(c.total),
        shown: c.shown === undefined ? name !== "free" && name !== "unknown" : !!c.shown,
      };
    });
    const bytes = decodeBase64(data.voxels || "");
    const records = Math.floor(bytes.length / RECORD_BYTES);
    for (const c of classes) {
      if (c.count > 0 && (c.start < 0 || c.start + c.count > records)) {
        throw new Error(`class ${c.name} lists voxels ${c.start}..${c.start + c.count} but the data holds ${records}`);
      }
    }
    const paths = (Array.isArray(data.paths) ? data.paths : []).map((p, i) => ({
      name: String(p.name || `path ${i + 1}`),
      kind: String(p.kind || "path"),
      ok: p.ok !== false,
      points: (Array.isArray(p.points) ? p.points : []).filter((q) => Array.isArray(q) && q.length >= 3),
      color: p.kind === "trajectory" ? PATH_COLORS.trajectory
        : p.kind === "flight" ? (p.ok === false ? PATH_COLORS.failed : PATH_COLORS.flight)
        : PATH_COLORS.other,
    }));
    return {
      model: String(data.model || ""),
      resolution,
      origin,
      initialColor: COLOR_MODES.some((m) => m.id === data.color) ? data.color : "class",
      height: Array.isArray(data.height) && data.height.length === 2 ? data.height.map(Number) : null,
      classes,
      bytes,
      view: new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength),
      paths,
    };
  }

  /** World bounding box {min, max} of the voxels in the given classes, or null if none. */
  function voxelBounds(map, classIndices) {
    // A 16-bit view of the records: index i is at words 8r, 8r+1, 8r+2 (little-endian hosts,
    // which all WebGL platforms are).
    const words = new Uint16Array(map.bytes.buffer, map.bytes.byteOffset, map.bytes.byteLength >> 1);
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    for (const ci of classIndices) {
      const c = map.classes[ci];
      for (let r = c.start, end = c.start + c.count; r < end; r++) {
        const o = r * 8;
        for (let k = 0; k < 3; k++) {
          const v = words[o + k];
          if (v < lo[k]) lo[k] = v;
          if (v > hi[k]) hi[k] = v;
        }
      }
    }
    if (lo[0] === Infinity) return null;
    const res = map.resolution;
    return {
      min: lo.map((v, k) => map.origin[k] + v * res),
      max: hi.map((v, k) => map.origin[k] + (v + 1) * res),
    };
  }

  function pathBounds(paths) {
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    for (const p of paths) {
      for (const q of p.points) {
        for (let k = 0; k < 3; k++) {
          lo[k] = Math.min(lo[k], q[k]);
          hi[k] = Math.max(hi[k], q[k]);
        }
      }
    }
    return lo[0] === Infinity ? null : { min: lo, max: hi };
  }

  /** The record of voxel r, read from the CPU copy of the voxel bytes. */
  function readRecord(map, r) {
    const v = map.view;
    const o = r * RECORD_BYTES;
    const i = [v.getUint16(o, true), v.getUint16(o + 2, true), v.getUint16(o + 4, true)];
    const centre = i.map((n, k) => map.origin[k] + (n + 0.5) * map.resolution);
    const m = (k) => v.getUint16(o + 6 + 2 * k, true) / 65535;
    return {
      index: r,
      class: CLASS_NAMES[v.getUint8(o + 14)] || "unknown",
      ix: i[0], iy: i[1], iz: i[2],
      x: centre[0], y: centre[1], z: centre[2],
      occupied: m(0), free: m(1), ambiguity: m(2), safety: m(3),
    };
  }

  // ------------------------------------------------------------------ shaders
  const GLSL_VIRIDIS = `
const vec3 VIRIDIS[${VIRIDIS.length}] = vec3[](
  ${VIRIDIS.map((c) => `vec3(${c.map((v) => (v / 255).toFixed(5)).join(", ")})`).join(",\n  ")});
vec3 viridis(float t) {
  float x = clamp(t, 0.0, 1.0) * ${(VIRIDIS.length - 1).toFixed(1)};
  int i = min(int(floor(x)), ${VIRIDIS.length - 2});
  return mix(VIRIDIS[i], VIRIDIS[i + 1], x - float(i));
}`;

  // Voxels are drawn by vertex pulling, one instanced draw call per class: the shader reads
  // each voxel's record from a texture holding the record bytes as they are (two RGBA16UI
  // texels per 16-byte record), and each instance is a block of voxels (CUBE_BLOCK cubes or
  // POINT_BLOCK points) rather than one voxel. Software renderers (SwiftShader, what a machine
  // without a GPU has) handle each instance as a separate draw, which made one instance per
  // voxel take seconds per frame for a few hundred thousand cubes; blocks keep the instance
  // count in the hundreds for a million voxels, and GPUs do not mind either way. The last
  // block's records past the class's end are moved outside the clip volume.
  //
  // A cube shows the three faces turned towards the eye. They share the cube corner nearest to
  // the eye and form a hexagon around it: 7 vertices and 6 triangles (CUBE_TRIANGLES, shared
  // by all cubes through one index buffer), mirrored per axis towards the eye. The fragment
  // shader finds each face's normal from screen-space derivatives. A point (free and unknown
  // voxels) is one vertex, sized to the voxel's projected edge.
  const CUBE_TRIANGLES = [0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5, 0, 5, 6, 0, 6, 1];
  const CUBE_BLOCK = 16384; // cubes per instance; the index buffer holds one block
  const POINT_BLOCK = 65536; // points per instance

  const VOXEL_VS = `#version 300 es
precision highp float;
precision highp int;
precision highp usampler2D;
uniform usampler2D uVoxels;    // records: (ix, iy, iz, occupied), (free, ambiguity, safety, class)
uniform mat4 uViewProj;
uniform vec3 uEye;
uniform vec3 uOrigin;          // minimum corner of voxel (0, 0, 0), relative to the scene anchor
uniform float uResolution;
uniform vec2 uHeight;          // z range of the height colour map, relative to the anchor
uniform int uMode;             // index in COLOR_MODES
uniform vec3 uClassColor[4];
uniform float uClassScale[4];
uniform int uStart;            // first record of this class
uniform int uEnd;              // one past its last record
uniform int uBlock;            // records per instance
uniform bool uPoints;          // one point per voxel instead of a cube
uniform vec2 uPointSize;       // device pixels per metre at unit depth, largest point size
out vec3 vWorld;
flat out vec3 vBase;
flat out uint vId;
${GLSL_VIRIDIS}
// The corner (+1, +1, +1) and the hexagon around it, in half edges; see CUBE_TRIANGLES.
const vec3 HEXAGON[7] = vec3[](vec3(1, 1, 1), vec3(1, -1, 1), vec3(1, -1, -1), vec3(1, 1, -1),
                               vec3(-1, 1, -1), vec3(-1, 1, 1), vec3(-1, -1, 1));
void main() {
  int record = uStart + gl_InstanceID * uBlock + (uPoints ? gl_VertexID : gl_VertexID / 7);
  if (record >= uEnd) {
    // Past the class's last record (in the last block): outside the clip volume, not drawn.
    gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
    gl_PointSize = 1.0;
    vWorld = vec3(0.0);
    vBase = vec3(0.0);
    vId = 0u;
    return;
  }
  int width = textureSize(uVoxels, 0).x;
  ivec2 at = ivec2((2 * record) % width, (2 * record) / width);  // width is even
  uvec4 a = texelFetch(uVoxels, at, 0);
  uvec4 b = texelFetch(uVoxels, at + ivec2(1, 0), 0);
  vec4 measure = vec4(a.w, b.xyz) / 65535.0;   // occupied, free, ambiguity, safety
  int cls = int(min(b.w & 255u, 3u));

  vec3 centre = uOrigin + (vec3(a.xyz) + 0.5) * uResolution;
  float edge = uResolution * uClassScale[cls];
  if (uPoints) {
    vWorld = centre;
    gl_Position = uViewProj * vec4(centre, 1.0);
    gl_PointSize = clamp(edge * uPointSize.x / gl_Position.w, 1.0, uPointSize.y);
  } else {
    vec3 towardsEye = vec3(greaterThanEqual(uEye, centre)) * 2.0 - 1.0;
    vWorld = centre + HEXAGON[gl_VertexID % 7] * towardsEye * 0.5 * edge;
    gl_Position = uViewProj * vec4(vWorld, 1.0);
  }

  if (uMode == 0) {
    vBase = uClassColor[cls];
  } else if (uMode == 1) {
    vBase = viridis((centre.z - uHeight.x) / max(uHeight.y - uHeight.x, 1e-6));
  } else {
    vBase = viridis(measure[uMode - 2]);
  }
  vId = uint(record + 1);
}`;

  const VOXEL_FS = `#version 300 es
precision highp float;
precision highp int;
uniform bool uPick;
uniform bool uPoints;
uniform vec3 uEye;
in vec3 vWorld;
flat in vec3 vBase;
flat in uint vId;
out vec4 outColor;
// Light from above and from -x: the x faces, y faces and top all differ in brightness.
const vec3 LIGHT = normalize(vec3(-0.5, 0.0, 0.85));
void main() {
  vec3 normal = vec3(0.0, 0.0, 1.0);   // points are lit like a top face
  float rim = 1.0;
  if (uPoints) {
    // Round dots, a little darker towards the rim.
    vec2 d = gl_PointCoord * 2.0 - 1.0;
    float r2 = dot(d, d);
    if (r2 > 1.0) discard;
    rim = 0.75 + 0.25 * sqrt(1.0 - r2);
  } else if (!uPick) {
    // The face's normal: the plane of the triangle, turned towards the eye.
    normal = normalize(cross(dFdx(vWorld), dFdy(vWorld)));
    if (dot(normal, uEye - vWorld) < 0.0) normal = -normal;
  }
  if (uPick) {
    // Record number + 1 in the red, green and blue bytes; 0 is the background.
    outColor = vec4(float(vId & 255u), float((vId >> 8) & 255u), float((vId >> 16) & 255u), 255.0) / 255.0;
  } else {
    // Half-Lambert directional light; the colour is lifted a little so that the faces of very
    // dark voxels still differ.
    float light = 0.5 + 0.5 * dot(normal, LIGHT);
    outColor = vec4((0.88 * vBase + 0.12) * (0.35 + 0.65 * light) * rim, 1.0);
  }
}`;

  // Lines (grid, axes, paths) are screen-space ribbons of a given width in pixels: each vertex
  // knows the other end of its segment and moves sideways by aOffset pixels.
  const LINE_VS = `#version 300 es
precision highp float;
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aOther;
layout(location = 2) in float aOffset;  // signed half width, CSS pixels
layout(location = 3) in vec4 aColor;
uniform mat4 uViewProj;
uniform vec2 uViewport;                 // device pixels
uniform float uPixelRatio;
uniform float uNear;                    // near plane distance
out vec4 vColor;
void main() {
  vec4 a = uViewProj * vec4(aPos, 1.0);
  vec4 b = uViewProj * vec4(aOther, 1.0);
  // A segment passing behind the eye is cut just in front of it, so that both of its ends
  // agree on its direction on screen (the part nearer than the near plane is clipped anyway).
  float cut = 0.5 * uNear;
  if (a.w < cut && b.w > cut) a = mix(a, b, (cut - a.w) / (b.w - a.w));
  if (b.w < cut && a.w > cut) b = mix(b, a, (cut - b.w) / (a.w - b.w));
  vec2 d = (b.xy / b.w - a.xy / a.w) * uViewport;
  vec2 n = length(d) > 1e-6 ? normalize(vec2(-d.y, d.x)) : vec2(0.0, 1.0);
  a.xy += n * aOffset * uPixelRatio * 2.0 / uViewport * a.w;
  gl_Position = a;
  vColor = aColor;
}`;

  const LINE_FS = `#version 300 es
precision highp float;
uniform float uAlpha;
in vec4 vColor;
out vec4 outColor;
void main() {
  outColor = vec4(vColor.rgb, vColor.a * uAlpha);
}`;

  function compileProgram(gl, vsSource, fsSource) {
    const program = gl.createProgram();
    for (const [type, source] of [[gl.VERTEX_SHADER, vsSource], [gl.FRAGMENT_SHADER, fsSource]]) {
      const shader = gl.createShader(type);
      gl.shaderSource(shader, source);
      gl.compileShader(shader);
      if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
        throw new Error("shader compilation failed: " + gl.getShaderInfoLog(shader));
      }
      gl.attachShader(program, shader);
    }
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS)) {
      throw new Error("shader link failed: " + gl.getProgramInfoLog(program));
    }
    const uniforms = {};
    const n = gl.getProgramParameter(program, gl.ACTIVE_UNIFORMS);
    for (let i = 0; i < n; i++) {
      const name = gl.getActiveUniform(program, i).name.replace(/\[0\]$/, "");
      uniforms[name] = gl.getUniformLocation(program, name);
    }
    return { program, uniforms };
  }

  // ------------------------------------------------------------------ geometry
  /** Collects screen-space line segments; each segment becomes two triangles (6 vertices). */
  class LineBuilder {
    constructor(anchor) {
      this.anchor = anchor;
      this.floats = [];
    }
    get vertexCount() {
      return this.floats.length / 11;
    }
    vertex(p, q, offset, color) {
      const o = this.anchor;
      this.floats.push(p[0] - o[0], p[1] - o[1], p[2] - o[2], q[0] - o[0], q[1] - o[1], q[2] - o[2],
        offset, color[0], color[1], color[2], color[3]);
    }
    segment(p, q, width, color) {
      const h = width / 2;
      // p+ p- q+ / p- q- q+, where q's offsets are negated because its direction is reversed.
      this.vertex(p, q, h, color);
      this.vertex(p, q, -h, color);
      this.vertex(q, p, -h, color);
      this.vertex(p, q, -h, color);
      this.vertex(q, p, h, color);
      this.vertex(q, p, -h, color);
    }
  }

  // ------------------------------------------------------------------ the viewer
  function start() {
    const map = loadMap(window.FUZZYVOX_DATA);
    const canvas = $("view");
    const gl = canvas.getContext("webgl2", { antialias: true, preserveDrawingBuffer: true });
    if (!gl) throw new Error("WebGL2 is not available in this browser (needed to draw the map)");
    canvas.addEventListener("webglcontextlost", (e) => {
      e.preventDefault();
      fail("the graphics context was lost; reload the page");
    });

    // State the user changes.
    const state = {
      mode: map.initialColor,
      shown: map.classes.map((c) => c.shown),
      pathsShown: true,
    };
    readHashOptions(state);

    // Boxes: the view frames the occupied voxels (or all voxels); axes and grid follow the
    // whole map; the depth range covers the map and the paths.
    const allClasses = [0, 1, 2, 3];
    const mapBox = voxelBounds(map, allClasses) || pathBounds(map.paths)
      || { min: map.origin.slice(), max: map.origin.map((v) => v + 1) };
    const focusBox = (map.classes[0].count > 0 && voxelBounds(map, [0])) || mapBox;
    const pBox = pathBounds(map.paths);
    const sceneBox = pBox
      ? { min: mapBox.min.map((v, k) => Math.min(v, pBox.min[k])), max: mapBox.max.map((v, k) => Math.max(v, pBox.max[k])) }
      : mapBox;
    const sceneRadius = Math.hypot(...sub(sceneBox.max, sceneBox.min)) / 2;
    // The GPU works in float32 relative to this anchor (the map's centre), so that maps far
    // from the world origin (geographic coordinates) keep their precision.
    const anchor = mapBox.min.map((v, k) => (v + mapBox.max[k]) / 2);
    const local = (p) => sub(p, anchor);
    const height = map.height && map.height[1] > map.height[0]
      ? map.height
      : [mapBox.min[2], Math.max(mapBox.max[2], mapBox.min[2] + map.resolution)];

    // ---- GPU resources
    const voxelProgram = compileProgram(gl, VOXEL_VS, VOXEL_FS);
    const lineProgram = compileProgram(gl, LINE_VS, LINE_FS);

    // The voxel records, uploaded once as they are: 8 u16 per record, two RGBA16UI texels.
    const records = Math.floor(map.bytes.byteLength / RECORD_BYTES);
    const maxSize = gl.getParameter(gl.MAX_TEXTURE_SIZE);
    const texWidth = Math.min(4096, maxSize);
    const texels = records * 2;
    const texHeight = Math.max(1, Math.ceil(texels / texWidth));
    if (texHeight > maxSize) throw new Error(`the map has too many voxels (${records}) for this graphics card`);
    const voxelTexture = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, voxelTexture);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA16UI, texWidth, texHeight);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    {
      const words = new Uint16Array(map.bytes.buffer, map.bytes.byteOffset, texels * 4);
      const fullRows = Math.floor(texels / texWidth);
      const rest = texels - fullRows * texWidth;
      const upload = (y, w, h, from) =>
        gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, y, w, h, gl.RGBA_INTEGER, gl.UNSIGNED_SHORT, words, from);
      if (fullRows > 0) upload(0, texWidth, fullRows, 0);
      if (rest > 0) upload(fullRows, rest, 1, fullRows * texWidth * 4);
    }
    // The voxel shader reads no vertex attributes, only the indices of the cube triangles.
    const cubeBlock = Math.min(CUBE_BLOCK, Math.max(1, ...map.classes
      .filter((c) => !CLASS_AS_POINTS[c.index]).map((c) => c.count)));
    const voxelVao = gl.createVertexArray();
    gl.bindVertexArray(voxelVao);
    {
      const cubes = cubeBlock;
      const indices = new Uint32Array(cubes * CUBE_TRIANGLES.length);
      for (let v = 0, i = 0; v < cubes; v++) {
        for (const corner of CUBE_TRIANGLES) indices[i++] = v * 7 + corner;
      }
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
    }
    gl.bindVertexArray(null);
    const maxPointSize = gl.getParameter(gl.ALIASED_POINT_SIZE_RANGE)[1];

    gl.useProgram(voxelProgram.program);
    const vu = voxelProgram.uniforms;
    gl.uniform3fv(vu.uOrigin, local(map.origin));
    gl.uniform1f(vu.uResolution, map.resolution);
    gl.uniform2fv(vu.uHeight, height.map((z) => z - anchor[2]));
    gl.uniform3fv(vu.uClassColor, map.classes.flatMap((c) => c.color.map((v) => v / 255)));
    gl.uniform1fv(vu.uClassScale, CLASS_SCALE);
    gl.uniform1i(vu.uVoxels, 0);

    // Lines: grid, then axes, then paths, in one buffer.
    const lines = new LineBuilder(anchor);
    const extent = sub(mapBox.max, mapBox.min);
    const gridStep = niceFloor(Math.max(extent[0], extent[1], map.resolution) / 8);
    {
      const z = mapBox.min[2];
      const x0 = Math.floor(mapBox.min[0] / gridStep) * gridStep;
      const x1 = Math.ceil(mapBox.max[0] / gridStep) * gridStep;
      const y0 = Math.floor(mapBox.min[1] / gridStep) * gridStep;
      const y1 = Math.ceil(mapBox.max[1] / gridStep) * gridStep;
      const grey = [0.78, 0.78, 0.76, 1];
      for (let x = x0; x <= x1 + gridStep / 2; x += gridStep) lines.segment([x, y0, z], [x, y1, z], 1, grey);
      for (let y = y0; y <= y1 + gridStep / 2; y += gridStep) lines.segment([x0, y, z], [x1, y, z], 1, grey);
    }
    const gridVertices = lines.vertexCount;
    const axisLength = extent.map((e) => Math.max(e, gridStep));
    const axisEnds = [0, 1, 2].map((k) => mapBox.min.map((v, j) => (j === k ? v + axisLength[k] : v)));
    const axisColors = [[0.85, 0.13, 0.13, 1], [0.09, 0.6, 0.2, 1], [0.14, 0.3, 0.88, 1]];
    axisEnds.forEach((end, k) => lines.segment(mapBox.min, end, 2.5, axisColors[k]));
    const axesVertices = lines.vertexCount - gridVertices;
    for (const p of map.paths) {
      for (let i = 1; i < p.points.length; i++) lines.segment(p.points[i - 1], p.points[i], 3, p.color);
    }
    const pathVertices = lines.vertexCount - gridVertices - axesVertices;

    const lineVao = gl.createVertexArray();
    gl.bindVertexArray(lineVao);
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(lines.floats), gl.STATIC_DRAW);
    const stride = 11 * 4;
    for (const [loc, size, offset] of [[0, 3, 0], [1, 3, 3], [2, 1, 6], [3, 4, 7]]) {
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, size, gl.FLOAT, false, stride, offset * 4);
    }
    gl.bindVertexArray(null);

    // Picking target: record numbers as colours, with its own depth buffer; sized lazily.
    const pick = { fbo: null, color: null, depth: null, width: 0, height: 0 };

    // ---- camera: orbit around a target, z up
    const camera = { target: [0, 0, 0], distance: 1, yaw: 0, pitch: 0 };

    /** Looks at the centre of the focus box from a 3/4 elevated angle, the box just in view. */
    function frameView() {
      const b = focusBox;
      camera.target = b.min.map((v, k) => (v + b.max[k]) / 2);
      camera.yaw = (235 * Math.PI) / 180; // from the south-west, x to the right
      camera.pitch = (35 * Math.PI) / 180;
      // Camera basis: back (target to eye), right, up.
      const back = normalize(sub(eyePosition(), camera.target));
      const right = normalize(cross([-back[0], -back[1], -back[2]], [0, 0, 1]));
      const up = cross(right, [-back[0], -back[1], -back[2]]);
      const tanY = Math.tan(FOV_Y / 2);
      const tanX = tanY * (canvas.clientWidth / Math.max(canvas.clientHeight, 1) || 1);
      // Smallest distance at which every corner is inside the view frustum.
      let distance = 4 * map.resolution;
      for (let corner = 0; corner < 8; corner++) {
        const c = [0, 1, 2].map((k) => ((corner >> k) & 1 ? b.max[k] : b.min[k]) - camera.target[k]);
        const depth = dot(c, back);
        distance = Math.max(distance, depth + Math.abs(dot(c, right)) / tanX, depth + Math.abs(dot(c, up)) / tanY);
      }
      camera.distance = distance * 1.08;
    }

    function eyePosition() {
      const { target: t, distance: d, yaw, pitch } = camera;
      return [
        t[0] + d * Math.cos(pitch) * Math.cos(yaw),
        t[1] + d * Math.cos(pitch) * Math.sin(yaw),
        t[2] + d * Math.sin(pitch),
      ];
    }

    const nearPlane = () => Math.max(camera.distance * 0.01, 1e-4);

    function viewProjection() {
      const aspect = canvas.width / Math.max(canvas.height, 1);
      const near = nearPlane();
      const far = camera.distance + 3 * sceneRadius + 10 * map.resolution;
      return multiply(perspective(FOV_Y, aspect, near, far), lookAt(local(eyePosition()), local(camera.target), [0, 0, 1]));
    }

    /** Metres per CSS pixel at the orbit target. */
    const metresPerPixel = () => (2 * camera.distance * Math.tan(FOV_Y / 2)) / Math.max(canvas.clientHeight, 1);

    // ---- drawing
    function resize() {
      const dpr = window.devicePixelRatio || 1;
      const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
      const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
      if (canvas.width !== w || canvas.height !== h) {
        canvas.width = w;
        canvas.height = h;
      }
    }

    /** Draws the visible classes: colours, or record numbers when picking. */
    function drawVoxels(viewProj, picking) {
      gl.useProgram(voxelProgram.program);
      gl.uniformMatrix4fv(vu.uViewProj, false, viewProj);
      gl.uniform3fv(vu.uEye, local(eyePosition()));
      gl.uniform1i(vu.uMode, COLOR_MODES.findIndex((m) => m.id === state.mode));
      gl.uniform1i(vu.uPick, picking ? 1 : 0);
      gl.bindVertexArray(voxelVao);
      gl.activeTexture(gl.TEXTURE0);
      gl.bindTexture(gl.TEXTURE_2D, voxelTexture);
      gl.uniform2f(vu.uPointSize, canvas.height / (2 * Math.tan(FOV_Y / 2)), maxPointSize);
      // Records of a class are contiguous: one instanced draw call per class.
      for (const c of map.classes) {
        if (!state.shown[c.index] || c.count === 0) continue;
        const points = CLASS_AS_POINTS[c.index];
        gl.uniform1i(vu.uPoints, points ? 1 : 0);
        gl.uniform1i(vu.uStart, c.start);
        gl.uniform1i(vu.uEnd, c.start + c.count);
        if (points) {
          const block = Math.min(POINT_BLOCK, c.count);
          gl.uniform1i(vu.uBlock, block);
          gl.drawArraysInstanced(gl.POINTS, 0, block, Math.ceil(c.count / block));
        } else {
          gl.uniform1i(vu.uBlock, cubeBlock);
          gl.drawElementsInstanced(gl.TRIANGLES, cubeBlock * CUBE_TRIANGLES.length,
            gl.UNSIGNED_INT, 0, Math.ceil(c.count / cubeBlock));
        }
      }
      gl.bindVertexArray(null);
    }

    function drawLines(viewProj) {
      const lu = lineProgram.uniforms;
      gl.useProgram(lineProgram.program);
      gl.uniformMatrix4fv(lu.uViewProj, false, viewProj);
      gl.uniform2f(lu.uViewport, canvas.width, canvas.height);
      gl.uniform1f(lu.uPixelRatio, canvas.width / Math.max(canvas.clientWidth, 1));
      gl.uniform1f(lu.uNear, nearPlane());
      gl.bindVertexArray(lineVao);
      // Pull lines slightly towards the eye so axes on voxel edges are not hidden.
      gl.enable(gl.POLYGON_OFFSET_FILL);
      gl.polygonOffset(-1, -2);
      gl.uniform1f(lu.uAlpha, 1);
      gl.drawArrays(gl.TRIANGLES, 0, gridVertices + axesVertices);
      if (state.pathsShown && pathVertices > 0) {
        // Faint pass without depth test so paths stay visible behind walls, then the real one.
        gl.enable(gl.BLEND);
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
        gl.disable(gl.DEPTH_TEST);
        gl.uniform1f(lu.uAlpha, 0.25);
        gl.drawArrays(gl.TRIANGLES, gridVertices + axesVertices, pathVertices);
        gl.enable(gl.DEPTH_TEST);
        gl.disable(gl.BLEND);
        gl.uniform1f(lu.uAlpha, 1);
        gl.drawArrays(gl.TRIANGLES, gridVertices + axesVertices, pathVertices);
      }
      gl.disable(gl.POLYGON_OFFSET_FILL);
      gl.bindVertexArray(null);
    }

    let frameRequested = false;

    function render() {
      frameRequested = false;
      resize();
      const viewProj = viewProjection();
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.viewport(0, 0, canvas.width, canvas.height);
      gl.enable(gl.DEPTH_TEST);
      gl.depthFunc(gl.LEQUAL);
      gl.clearColor(BACKGROUND[0], BACKGROUND[1], BACKGROUND[2], 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      drawVoxels(viewProj, false);
      drawLines(viewProj);
      updateOverlays(viewProj);
    }

    function requestRender() {
      if (!frameRequested) {
        frameRequested = true;
        requestAnimationFrame(render);
      }
    }

    /** The record under CSS pixel (x, y) of the canvas, or null. Renders one pixel of ids. */
    function pickAt(x, y) {
      resize();
      const sx = canvas.width / Math.max(canvas.clientWidth, 1);
      const sy = canvas.height / Math.max(canvas.clientHeight, 1);
      const px = Math.floor(x * sx);
      const py = canvas.height - 1 - Math.floor(y * sy);
      if (px < 0 || py < 0 || px >= canvas.width || py >= canvas.height) return null;
      if (!pick.fbo || pick.width !== canvas.width || pick.height !== canvas.height) {
        if (pick.fbo) {
          gl.deleteFramebuffer(pick.fbo);
          gl.deleteRenderbuffer(pick.color);
          gl.deleteRenderbuffer(pick.depth);
        }
        pick.width = canvas.width;
        pick.height = canvas.height;
        pick.fbo = gl.createFramebuffer();
        pick.color = gl.createRenderbuffer();
        pick.depth = gl.createRenderbuffer();
        gl.bindRenderbuffer(gl.RENDERBUFFER, pick.color);
        gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA8, pick.width, pick.height);
        gl.bindRenderbuffer(gl.RENDERBUFFER, pick.depth);
        gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, pick.width, pick.height);
        gl.bindFramebuffer(gl.FRAMEBUFFER, pick.fbo);
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, pick.color);
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, pick.depth);
      }
      gl.bindFramebuffer(gl.FRAMEBUFFER, pick.fbo);
      gl.viewport(0, 0, pick.width, pick.height);
      // Only the pixel under the cursor is rasterised.
      gl.enable(gl.SCISSOR_TEST);
      gl.scissor(px, py, 1, 1);
      gl.enable(gl.DEPTH_TEST);
      gl.depthFunc(gl.LEQUAL);
      gl.disable(gl.BLEND);
      gl.clearColor(0, 0, 0, 0);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      drawVoxels(viewProjection(), true);
      const pixel = new Uint8Array(4);
      gl.readPixels(px, py, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
      gl.disable(gl.SCISSOR_TEST);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      const id = pixel[0] | (pixel[1] << 8) | (pixel[2] << 16);
      return id === 0 ? null : readRecord(map, id - 1);
    }

    // ---- HTML overlays: axis labels, scale bar, tooltip
    const axisLabels = [$("axis-x"), $("axis-y"), $("axis-z")];
    const scaleBar = $("scalebar-bar");
    const scaleLabel = $("scalebar-label");
    const tooltip = $("tooltip");

    function updateOverlays(viewProj) {
      const w = canvas.clientWidth;
      const h = canvas.clientHeight;
      axisEnds.forEach((end, k) => {
        // A little beyond the end of the axis.
        const beyond = end.map((v, j) => (j === k ? v + 0.06 * axisLength[k] + 2 * map.resolution : v));
        const s = toScreen(viewProj, local(beyond), w, h);
        const label = axisLabels[k];
        const visible = s && s[0] >= 0 && s[0] <= w && s[1] >= 0 && s[1] <= h;
        label.style.display = visible ? "block" : "none";
        if (visible) {
          label.style.left = `${s[0]}px`;
          label.style.top = `${s[1]}px`;
        }
      });
      const mpp = metresPerPixel();
      const metres = niceFloor(110 * mpp);
      scaleBar.parentElement.style.display = "block";
      scaleBar.style.width = `${Math.round(metres / mpp)}px`;
      scaleLabel.textContent = formatLength(metres);
    }

    function showTooltip(record, x, y) {
      if (!record) {
        tooltip.style.display = "none";
        return;
      }
      const f = (v) => v.toFixed(3);
      tooltip.innerHTML = "";
      tooltip.append(
        el("div", {}, [el("b", { textContent: `${record.class} voxel` }), ` [${record.ix}, ${record.iy}, ${record.iz}]`]),
        el("div", { textContent: `centre ${record.x.toFixed(2)}, ${record.y.toFixed(2)}, ${record.z.toFixed(2)} m` }),
        el("div", { textContent: `occupied ${f(record.occupied)} · free ${f(record.free)}` }),
        el("div", { textContent: `ambiguity ${f(record.ambiguity)} · safety ${f(record.safety)}` }),
      );
      tooltip.style.display = "block";
      // Keep the tooltip inside the window.
      const right = x + 14 + tooltip.offsetWidth > window.innerWidth;
      const below = y + 14 + tooltip.offsetHeight > window.innerHeight;
      tooltip.style.left = `${right ? x - 10 - tooltip.offsetWidth : x + 14}px`;
      tooltip.style.top = `${below ? y - 10 - tooltip.offsetHeight : y + 14}px`;
    }

    // ---- legend
    const modeSelect = $("color-mode");
    for (const m of COLOR_MODES) modeSelect.append(el("option", { value: m.id, textContent: m.label }));
    modeSelect.addEventListener("change", () => setColor(modeSelect.value));
    $("reset-view").addEventListener("click", () => {
      frameView();
      requestRender();
    });

    const drawnTotal = map.classes.reduce((s, c) => s + c.count, 0);
    $("info").textContent = [
      map.model && `${map.model} map`,
      `voxel ${formatLength(map.resolution)}`,
      `grid ${formatLength(gridStep)}`,
    ].filter(Boolean).join(" · ");

    const classBox = $("classes");
    classBox.append(el("div", { className: "section-title", textContent: "classes" }));
    const checkboxes = map.classes.map((c) => {
      const box = el("input", { type: "checkbox", id: `toggle-${c.name}`, checked: state.shown[c.index] });
      box.addEventListener("change", () => setVisible(c.name, box.checked));
      const swatch = el("span", { className: "swatch" });
      swatch.style.background = `rgb(${c.color.join(",")})`;
      const count = c.count < c.total ? `${formatCount(c.count)} of ${formatCount(c.total)}` : formatCount(c.count);
      classBox.append(el("label", { className: "row", title: `${c.name} voxels drawn` }, [
        box, swatch, el("span", { className: "name", textContent: c.name }), el("span", { className: "count", textContent: count }),
      ]));
      return box;
    });
    if (drawnTotal === 0) classBox.append(el("div", { className: "empty", textContent: "empty map" }));

    const pathBox = $("paths");
    if (map.paths.length > 0) {
      const box = el("input", { type: "checkbox", id: "toggle-paths", checked: state.pathsShown });
      box.addEventListener("change", () => {
        state.pathsShown = box.checked;
        requestRender();
      });
      pathBox.append(el("label", { className: "row section-title" }, [box, el("span", { className: "name", textContent: "paths" })]));
      for (const p of map.paths) {
        const swatch = el("span", { className: "line-swatch" });
        swatch.style.background = `rgb(${p.color.slice(0, 3).map((v) => Math.round(v * 255)).join(",")})`;
        const note = `${p.kind}${p.ok ? "" : ", failed"} · ${p.points.length} points`;
        pathBox.append(el("div", { className: "row" }, [
          swatch, el("span", { className: "name", textContent: p.name }), el("span", { className: "count", textContent: note }),
        ]));
      }
    }

    // Colour bar: drawn once from the JS viridis; labels depend on the mode.
    {
      const bar = $("colorbar-canvas");
      const ctx = bar.getContext("2d");
      const image = ctx.createImageData(bar.width, 1);
      for (let x = 0; x < bar.width; x++) {
        const [r, g, b] = viridis(x / (bar.width - 1));
        image.data.set([r, g, b, 255], x * 4);
      }
      ctx.putImageData(image, 0, 0);
    }

    function updateLegend() {
      modeSelect.value = state.mode;
      const measure = state.mode !== "class";
      $("colorbar").style.display = measure ? "block" : "none";
      for (const s of classBox.querySelectorAll(".swatch")) s.style.visibility = measure ? "hidden" : "visible";
      if (state.mode === "height") {
        $("colorbar-min").textContent = `z ${height[0].toFixed(2)} m`;
        $("colorbar-max").textContent = `${height[1].toFixed(2)} m`;
        $("colorbar-name").textContent = "height";
      } else {
        $("colorbar-min").textContent = "0";
        $("colorbar-max").textContent = "1";
        $("colorbar-name").textContent = COLOR_MODES.find((m) => m.id === state.mode).label;
      }
      checkboxes.forEach((box, i) => {
        box.checked = state.shown[i];
      });
    }

    // ---- option changes
    function setVisible(name, visible) {
      const i = CLASS_NAMES.indexOf(name);
      if (i < 0) throw new Error(`no class named ${name}`);
      state.shown[i] = !!visible;
      updateLegend();
      requestRender();
    }

    function setColor(mode) {
      if (!COLOR_MODES.some((m) => m.id === mode)) throw new Error(`no colour mode named ${mode}`);
      state.mode = mode;
      updateLegend();
      requestRender();
    }

    // ---- input: orbit, pan, zoom, hover
    let drag = null;
    let hover = null;
    let hoverRequested = false;

    function canvasPoint(e) {
      const r = canvas.getBoundingClientRect();
      return [e.clientX - r.left, e.clientY - r.top];
    }

    canvas.addEventListener("pointerdown", (e) => {
      if (e.button !== 0 && e.button !== 1 && e.button !== 2) return;
      const pan = e.button !== 0 || e.shiftKey;
      drag = { pan, x: e.clientX, y: e.clientY };
      canvas.setPointerCapture(e.pointerId);
      canvas.classList.add("dragging");
      hover = null;
      showTooltip(null);
    });

    canvas.addEventListener("pointermove", (e) => {
      if (drag) {
        const dx = e.clientX - drag.x;
        const dy = e.clientY - drag.y;
        drag.x = e.clientX;
        drag.y = e.clientY;
        if (drag.pan) {
          // Move the target so that the map follows the pointer.
          const eye = eyePosition();
          const forward = normalize(sub(camera.target, eye));
          const right = normalize(cross(forward, [0, 0, 1]));
          const up = cross(right, forward);
          const mpp = metresPerPixel();
          camera.target = camera.target.map((v, k) => v - right[k] * dx * mpp + up[k] * dy * mpp);
        } else {
          camera.yaw -= dx * 0.008;
          camera.pitch = Math.min(1.55, Math.max(-1.55, camera.pitch + dy * 0.008));
        }
        requestRender();
        return;
      }
      // Hover: pick at most once per animation frame.
      hover = { point: canvasPoint(e), client: [e.clientX, e.clientY] };
      if (!hoverRequested) {
        hoverRequested = true;
        requestAnimationFrame(() => {
          hoverRequested = false;
          if (!hover || drag) return;
          showTooltip(pickAt(...hover.point), ...hover.client);
        });
      }
    });

    const endDrag = (e) => {
      if (!drag) return;
      drag = null;
      canvas.classList.remove("dragging");
      if (canvas.hasPointerCapture(e.pointerId)) canvas.releasePointerCapture(e.pointerId);
    };
    canvas.addEventListener("pointerup", endDrag);
    canvas.addEventListener("pointercancel", endDrag);
    canvas.addEventListener("pointerleave", () => {
      hover = null;
      showTooltip(null);
    });
    canvas.addEventListener("contextmenu", (e) => e.preventDefault());
    canvas.addEventListener("wheel", (e) => {
      e.preventDefault();
      const lines = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1;
      const factor = Math.exp(Math.max(-1, Math.min(1, e.deltaY * lines * 0.0015)));
      camera.distance = Math.min(1e6, Math.max(map.resolution, camera.distance * factor));
      showTooltip(null);
      requestRender();
    }, { passive: false });
    canvas.addEventListener("dblclick", () => {
      frameView();
      requestRender();
    });
    window.addEventListener("resize", requestRender);

    // ---- first frame, synchronously
    updateLegend();
    resize();
    frameView();
    render();
    gl.finish();
    // finish() may return before the frame is drawn (it does in Chromium); reading one pixel
    // waits for it, so the ready time includes the first frame.
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));

    window.viewer = {
      counts: Object.fromEntries(map.classes.map((c) => [c.name, c.count])),
      setVisible,
      setColor,
      pick: pickAt,
      render,
    };
  }

  /** Options in the URL: #hide=occupied,free&show=unknown&color=height */
  function readHashOptions(state) {
    for (const part of location.hash.replace(/^#/, "").split("&")) {
      const eq = part.indexOf("=");
      if (eq < 0) continue;
      const key = decodeURIComponent(part.slice(0, eq));
      const values = decodeURIComponent(part.slice(eq + 1)).split(",").filter(Boolean);
      if (key === "hide" || key === "show") {
        for (const name of values) {
          const i = CLASS_NAMES.indexOf(name);
          if (i >= 0) state.shown[i] = key === "show";
        }
      } else if (key === "color" && COLOR_MODES.some((m) => m.id === values[0])) {
        state.mode = values[0];
      }
    }
  }

  try {
    start();
    const ms = Math.round(performance.now());
    body.dataset.readyMs = String(ms);
    body.dataset.status = "ready";
    console.log("fuzzyvox-view ready in " + ms + " ms");
  } catch (err) {
    fail(err && err.message ? err.message : String(err));
  }
})();

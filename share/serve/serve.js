// serve.js: the page of `bumpbake serve`. It follows the server's state
// through server-sent events ("events"), fetches the textures of each new
// bake ("map/NAME": 8-bit RGBA, X-Bake-Id saying which bake; an edit of
// the bake shown as the rectangle it changed, "map/NAME?since=ID"), draws them
// with WebGL 2 (serve.frag.glsl after shaders/ssbump_relief.glsl), relights
// as the light is dragged, and sends the controls ("params") and the write
// action ("write"). The controls are the library's: the page builds them
// from "controls" (the rows of the options serve offers: name, type, help,
// default, range), their values are the state's, and nothing of them is
// the page's own. The picture zooms and
// pans, shows the bake before in turns with the last (A/B), and is dimmed,
// saying why, whenever it is not the maps of now. Once a bake's maps are
// drawn, <body data-drawn-bake> holds its id and data-drawn-at the time
// (Date.now()), for tests.
"use strict";

const $ = (id) => document.getElementById(id);
const canvas = $("canvas");
const gl = canvas.getContext("webgl2", { preserveDrawingBuffer: true, antialias: false });
// The maps' textures by name, and the texture unit of each; the height
// texture (unit 4) is made from normal_height's alpha.
const TEXTURES = ["ssbump_ao", "normal_height", "bent", "weights", "albedo"];
const UNITS = { ssbump_ao: 0, normal_height: 1, bent: 2, weights: 3, height: 4, albedo: 5 };
const light = { azimuth: 135, elevation: 45 };  // render's default light
let program = null, uniforms = {};
// A bake's maps on the GPU: {id, width, height, tex: {name: WebGLTexture}}.
// current is the last bake loaded, previous the one before it (A/B).
let current = null, previous = null, showB = false;
let state = null;         // the server's last state
let loading = 0;          // 1 while a bake's maps are fetched
let drawPending = false;
let drawnFrom = "";        // the state's values the picture was last drawn with (showState)
const bakeScale = {};      // each bake's --scale by id: the depth of its relief
const bakeBasis = {};      // each bake's basis directions by id: the ssbump's lighting
const SSBUMP_MODES = [0, 8];  // the modes that light the ssbump with the basis
const LIT_MODES = [0, 1, 2, 8];  // the modes a light (and a colour map) lights
const RELIEF_MODE = 8;           // the one mode seen from a camera
let controls = [];        // the server's "controls": the options the page offers, as rows
let ranges = {};          // the picture's ranges: {view_elevation, light_elevation: {min, max, ...}}
// The camera on the picture: canvas pixels a texel (0: fit the maps), and
// the texel at the picture's centre.
const camera = { zoom: 0, cx: 0, cy: 0 };

function fail(message) {
  $("error").textContent = message;
}

function shown() {
  return showB && previous ? previous : current;
}

// -------------------------------------------------------------- the light

// v within range r ({min, max}, either missing: no bound).
function clamp(v, r) {
  if (r && r.max !== undefined) v = Math.min(r.max, v);
  if (r && r.min !== undefined) v = Math.max(r.min, v);
  return v;
}

// bb_light_direction: azimuth 0 from the right, 90 from the top; +y is down.
function direction(azimuthDeg, elevationDeg) {
  const a = azimuthDeg * Math.PI / 180, e = elevationDeg * Math.PI / 180;
  return [Math.cos(e) * Math.cos(a), -Math.cos(e) * Math.sin(a), Math.sin(e)];
}

function showLight() {
  const text = light.azimuth.toFixed(0) + "," + light.elevation.toFixed(0);
  $("light-text").textContent = text;
  $("light-readout").textContent = "light " + text;
}

// The point under the pointer is the light's projection on the picture.
function dragLight(event) {
  const r = canvas.getBoundingClientRect();
  const dx = (event.clientX - r.left) / r.width * 2 - 1;
  const dy = 1 - (event.clientY - r.top) / r.height * 2;
  const radius = Math.min(1, Math.hypot(dx, dy));
  light.azimuth = (Math.atan2(dy, dx) * 180 / Math.PI + 360) % 360;
  light.elevation = clamp(Math.acos(radius) * 180 / Math.PI, ranges.light_elevation);
  showLight();
  requestDraw();
}

// ------------------------------------------------------- zoom, pan, 1:1

// The maps' extent on the picture (tiled 2 x 2 or not), texels.
function extent() {
  const m = shown(), tile = $("tile").checked ? 2 : 1;
  return m ? [m.width * tile, m.height * tile] : [1, 1];
}

function fitZoom() {
  const [w, h] = extent();
  return Math.min(canvas.width / w, canvas.height / h);
}

function zoomNow() {
  return camera.zoom || fitZoom();
}

function showZoom() {
  $("zoom-text").textContent = camera.zoom ? Math.round(camera.zoom * 100) + "%"
                                           : "fit (" + Math.round(fitZoom() * 100) + "%)";
}

function setZoom(zoom, px, py) {
  // the texel under canvas pixel (px, py) stays under it
  const [w, h] = extent(), z0 = zoomNow();
  const cx = camera.zoom ? camera.cx : w / 2, cy = camera.zoom ? camera.cy : h / 2;
  const tx = cx + (px - canvas.width / 2) / z0, ty = cy + (py - canvas.height / 2) / z0;
  camera.zoom = Math.min(64, Math.max(1 / 64, zoom));
  camera.cx = tx - (px - canvas.width / 2) / camera.zoom;
  camera.cy = ty - (py - canvas.height / 2) / camera.zoom;
  showZoom();
  requestDraw();
}

function fit() {
  camera.zoom = 0;
  showZoom();
  requestDraw();
}

function canvasPoint(event) {
  const r = canvas.getBoundingClientRect();
  return [(event.clientX - r.left) * canvas.width / r.width,
          (event.clientY - r.top) * canvas.height / r.height];
}

canvas.addEventListener("wheel", (e) => {
  e.preventDefault();
  const [px, py] = canvasPoint(e);
  setZoom(zoomNow() * Math.pow(1.25, e.deltaY < 0 ? 1 : -1), px, py);
}, { passive: false });

let panFrom = null;
canvas.addEventListener("pointerdown", (e) => {
  canvas.setPointerCapture(e.pointerId);
  if (e.button === 1 || e.shiftKey) {
    if (!camera.zoom) setZoom(fitZoom(), canvas.width / 2, canvas.height / 2);
    panFrom = { x: e.clientX, y: e.clientY, cx: camera.cx, cy: camera.cy };
    e.preventDefault();
    return;
  }
  dragLight(e);
});
canvas.addEventListener("pointermove", (e) => {
  if (!e.buttons) return;
  if (panFrom) {
    const r = canvas.getBoundingClientRect(), z = zoomNow();
    camera.cx = panFrom.cx - (e.clientX - panFrom.x) * canvas.width / r.width / z;
    camera.cy = panFrom.cy - (e.clientY - panFrom.y) * canvas.height / r.height / z;
    requestDraw();
  } else {
    dragLight(e);
  }
});
canvas.addEventListener("pointerup", () => { panFrom = null; });
canvas.addEventListener("auxclick", (e) => e.preventDefault());
$("zoom-fit").addEventListener("click", fit);
$("zoom-1").addEventListener("click", () => setZoom(1, canvas.width / 2, canvas.height / 2));

// ------------------------------------------------------------------ A/B

function showAB() {
  const ab = $("ab");
  ab.disabled = !previous;
  ab.classList.toggle("on", showB && !!previous);
  $("ab-text").textContent = !current ? "" : showB && previous
    ? "B: bake " + previous.id + " (the one before)" : "A: bake " + current.id +
      (previous ? " (B: bake " + previous.id + ")" : "");
}

function toggleAB() {
  showB = !showB && !!previous;
  showAB();
  showStale();
  requestDraw();
}

$("ab").addEventListener("click", toggleAB);
document.addEventListener("keydown", (e) => {
  if ((e.key === "b" || e.key === "B") && !(e.target instanceof HTMLInputElement)) toggleAB();
});

// ---------------------------------------------------------------- WebGL

function compile(type, source) {
  const s = gl.createShader(type);
  gl.shaderSource(s, source);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS))
    throw new Error("shader: " + gl.getShaderInfoLog(s));
  return s;
}

async function setup() {
  if (!gl) throw new Error("this browser has no WebGL 2");
  const [relief, frag, got] = await Promise.all(
    ["ssbump_relief.glsl", "serve.frag.glsl", "controls"].map((f) => fetch(f).then(
      (r) => f === "controls" ? r.json() : r.text())));
  controls = got.controls;
  ranges = got.view;
  buildControls();
  bound($("view-el"), ranges.view_elevation);
  const vs = "#version 300 es\nin vec2 aPos;\nvoid main() { gl_Position = vec4(aPos, 0.0, 1.0); }\n";
  const fs = "#version 300 es\nprecision highp float;\nprecision highp int;\n" +
             "precision highp sampler2D;\n" + relief + "\n" + frag;
  program = gl.createProgram();
  gl.attachShader(program, compile(gl.VERTEX_SHADER, vs));
  gl.attachShader(program, compile(gl.FRAGMENT_SHADER, fs));
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS))
    throw new Error("program: " + gl.getProgramInfoLog(program));
  gl.useProgram(program);
  const buffer = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
  gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 1, -1, -1, 1, 1, 1]), gl.STATIC_DRAW);
  const pos = gl.getAttribLocation(program, "aPos");
  gl.enableVertexAttribArray(pos);
  gl.vertexAttribPointer(pos, 2, gl.FLOAT, false, 0, 0);
  const count = gl.getProgramParameter(program, gl.ACTIVE_UNIFORMS);
  for (let i = 0; i < count; i++) {
    const name = gl.getActiveUniform(program, i).name;
    uniforms[name] = gl.getUniformLocation(program, name);
  }
  uniforms.uBasis = gl.getUniformLocation(program, "uBasis");  // the array, from element 0
  const samplers = { uSsbumpAo: "ssbump_ao", uNormalHeight: "normal_height", uBent: "bent",
                     uWeights: "weights", uHeight: "height", uAlbedo: "albedo" };
  for (const [name, texture] of Object.entries(samplers))
    gl.uniform1i(uniforms[name], UNITS[texture]);
}

function makeTexture(unit, internal, format, w, h, bytes) {
  const t = gl.createTexture();
  gl.activeTexture(gl.TEXTURE0 + unit);
  gl.bindTexture(gl.TEXTURE_2D, t);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);  // as render samples
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);  // the maps tile
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.REPEAT);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, gl.UNSIGNED_BYTE, bytes);
  return t;
}

function freeMaps(m) {
  if (m) for (const t of Object.values(m.tex)) gl.deleteTexture(t);
}

// The textures each mode reads (serve.frag.glsl), and the albedo where it
// is drawn.
function texturesOf(mode) {
  const names = { 0: ["ssbump_ao"], 3: ["ssbump_ao"], 6: ["ssbump_ao"], 4: ["bent"],
                  5: ["weights"] }[mode] || ["ssbump_ao", "normal_height"];
  return albedoUsed(mode) ? names.concat(["albedo"]) : names;
}

function albedoUsed(mode) {
  return !!(state && state.params.albedo_file && $("albedo").checked && LIT_MODES.includes(mode));
}

// Fetches names of the last good bake; they must all be of one bake (id,
// or any when id is 0). Returns {id, w, h, data, regions} or null when a
// newer bake landed in between. With since (a bake held whole), a bake
// that is an edit of it comes as the rectangles it changed: regions[i] is
// [x0, y0, width, height] of data[i] (X-Region), null for a whole texture.
async function fetchMaps(names, id, since) {
  const query = since ? "?since=" + since : "";
  const replies = await Promise.all(names.map((name) => fetch("map/" + name + query)));
  for (const r of replies)
    if (!r.ok) {
      if (r.status === 503) return null;  // a newer bake landed first: fetch that one
      throw new Error("map: " + r.status + " " + (await r.text()));
    }
  const ids = replies.map((r) => Number(r.headers.get("X-Bake-Id")));
  const data = await Promise.all(replies.map((r) => r.arrayBuffer()));
  if (ids.some((x) => x !== ids[0]) || (id && ids[0] !== id)) return null;
  const regions = replies.map((r) => {
    const v = r.headers.get("X-Region");
    return v === null ? null : v.split(",").map(Number);
  });
  return { id: ids[0], w: Number(replies[0].headers.get("X-Width")),
           h: Number(replies[0].headers.get("X-Height")), data: data, regions: regions };
}

function uploadMaps(m, names, got) {
  names.forEach((name, i) => {
    const bytes = new Uint8Array(got.data[i]);
    m.tex[name] = makeTexture(UNITS[name], gl.RGBA8, gl.RGBA, got.w, got.h, bytes);
    if (name === "normal_height") {
      // the relief reads the height's first channel (ssbump_relief.glsl's relief_h)
      m.tex.height = makeTexture(UNITS.height, gl.R8, gl.RED, got.w, got.h, alphaOf(bytes));
    }
  });
}

// The alpha bytes of RGBA texels: the height of normal_height.
function alphaOf(bytes) {
  const n = bytes.length / 4, alpha = new Uint8Array(n);
  for (let k = 0; k < n; k++) alpha[k] = bytes[4 * k + 3];
  return alpha;
}

// A copy of texture t (w x h, on the GPU: a bake's maps stay whole for A/B).
let copyFrom = null;
function copyTexture(unit, t, internal, format, w, h) {
  const copy = makeTexture(unit, internal, format, w, h, null);
  if (!copyFrom) copyFrom = gl.createFramebuffer();
  gl.bindFramebuffer(gl.READ_FRAMEBUFFER, copyFrom);
  gl.framebufferTexture2D(gl.READ_FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, t, 0);
  gl.copyTexSubImage2D(gl.TEXTURE_2D, 0, 0, 0, 0, 0, w, h);
  gl.bindFramebuffer(gl.READ_FRAMEBUFFER, null);
  return copy;
}

// The maps of an edit of bake base (whole): base's textures copied, each
// with the rectangle the edit changed (got, fetched since base) written in.
function patchedMaps(base, names, got) {
  const m = { id: got.id, width: got.w, height: got.h, tex: {} };
  for (const [name, t] of Object.entries(base.tex)) {
    const r8 = name === "height";
    m.tex[name] = copyTexture(UNITS[name], t, r8 ? gl.R8 : gl.RGBA8, r8 ? gl.RED : gl.RGBA,
                              got.w, got.h);
  }
  names.forEach((name, i) => {
    const [x0, y0, w, h] = got.regions[i], bytes = new Uint8Array(got.data[i]);
    if (!w || !h) return;
    gl.activeTexture(gl.TEXTURE0 + UNITS[name]);
    gl.bindTexture(gl.TEXTURE_2D, m.tex[name]);
    gl.texSubImage2D(gl.TEXTURE_2D, 0, x0, y0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, bytes);
    if (name === "normal_height") {
      gl.activeTexture(gl.TEXTURE0 + UNITS.height);
      gl.bindTexture(gl.TEXTURE_2D, m.tex.height);
      gl.texSubImage2D(gl.TEXTURE_2D, 0, x0, y0, w, h, gl.RED, gl.UNSIGNED_BYTE,
                       alphaOf(bytes));
    }
  });
  m.whole = true;
  return m;
}

// current becomes m; the bake it replaces becomes B if it was whole.
function showMaps(m) {
  const before = current;
  current = m;
  if (before && before !== previous && before.whole) {
    freeMaps(previous);
    previous = before;
  } else if (before && before !== previous) {
    freeMaps(before);  // cut short by this one: not a bake to compare with
  }
  showB = false;
  fitCanvas();
  draw();
}

// An edit of the bake shown (whole) comes as what it changed: asked for
// every texture the shown bake has, since it. True when it was drawn so;
// false when the server sent whole textures (not an edit of it: they are
// dropped and fetched as a new bake's) or a newer bake landed in between.
async function loadEdit() {
  const base = current;
  const names = Object.keys(base.tex).filter((name) => name !== "height");
  const got = await fetchMaps(names, 0, base.id);
  if (!got || got.regions.some((r) => r === null) || current !== base ||
      got.w !== base.width || got.h !== base.height)
    return false;
  showMaps(patchedMaps(base, names, got));
  return true;
}

// A new bake: an edit of the bake shown as the texels it changed; else
// first the textures the picture shown needs, drawn at once, then the
// others (so a save shows as soon as its ssbump has arrived).
// The bake it replaces becomes B once the new one is whole.
async function loadMaps() {
  loading = 1;
  try {
    for (;;) {
      const bake = state && state.bake;
      if (current && current.whole && bake && bake.base === current.id && await loadEdit())
        break;
      const first = texturesOf(Number($("mode").value));
      const got = await fetchMaps(first, 0, 0);
      if (!got) continue;  // a bake landed in between: again
      const m = { id: got.id, width: got.w, height: got.h, tex: {} };
      uploadMaps(m, first, got);
      showMaps(m);
      const rest = TEXTURES.filter((t) => !first.includes(t) &&
                                         (t !== "albedo" || (state && state.bake && state.bake.albedo)));
      const others = rest.length ? await fetchMaps(rest, got.id, 0) : { data: [] };
      if (!others) continue;  // newer maps already: load them whole
      uploadMaps(m, rest, { w: got.w, h: got.h, data: others.data });
      m.whole = true;
      draw();
      break;
    }
  } finally {
    loading = 0;
    showAB();
    showStale();
  }
  if (state && state.bake && state.bake.id > current.id) loadMaps();
}

// The picture keeps the maps' shape, its longer side 640 pixels.
function fitCanvas() {
  const m = shown(), tall = m.height > m.width;
  const w = tall ? Math.round(640 * m.width / m.height) : 640;
  const h = tall ? 640 : Math.round(640 * m.height / m.width);
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
    canvas.style.width = w + "px";
    canvas.style.height = h + "px";
  }
  showZoom();
}

function requestDraw() {
  if (drawPending || !current) return;
  drawPending = true;
  requestAnimationFrame(() => { drawPending = false; draw(); });
}

// A view input's value within the library's range, the box showing the
// value drawn once it is left (0 is the range's bottom, not the default).
function viewValue(input, r, fallback, commit) {
  const typed = input.value.trim() === "" ? NaN : Number(input.value);
  const v = Number.isFinite(typed) ? clamp(typed, r) : fallback;
  if (commit && String(v) !== input.value) input.value = String(v);
  return v;
}

function draw() {
  const m = shown();
  if (!m) return;
  const mode = Number($("mode").value), [w, h] = extent();
  for (const [name, t] of Object.entries(m.tex)) {
    gl.activeTexture(gl.TEXTURE0 + UNITS[name]);
    gl.bindTexture(gl.TEXTURE_2D, t);
  }
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.uniform2f(uniforms.uSize, m.width, m.height);
  gl.uniform2f(uniforms.uCanvas, canvas.width, canvas.height);
  gl.uniform2f(uniforms.uExtent, w, h);
  gl.uniform1f(uniforms.uZoom, zoomNow());
  gl.uniform2f(uniforms.uCenter, camera.zoom ? camera.cx : w / 2, camera.zoom ? camera.cy : h / 2);
  gl.uniform1i(uniforms.uMode, mode);
  gl.uniform3fv(uniforms.uLight, direction(light.azimuth, light.elevation));
  const color = state ? state.params.light_color : [1, 1, 1];
  gl.uniform3fv(uniforms.uLightColor, LIT_MODES.includes(mode) ? color : [1, 1, 1]);
  gl.uniform1f(uniforms.uUseAlbedo, albedoUsed(mode) && m.tex.albedo ? 1 : 0);
  gl.uniform1f(uniforms.uNormalYUp, state && state.bake && state.bake.normal_y_up ? 1 : 0);
  // render's camera (job_init): towards it, the screen's right, the stretch
  const az = viewValue($("view-az"), null, 270, false);
  const el = viewValue($("view-el"), ranges.view_elevation, 30, false);
  const view = direction(az, el);
  let toward = [view[0], view[1]];
  const horizontal = Math.hypot(view[0], view[1]);
  if (horizontal > 1e-9) toward = [view[0] / horizontal, view[1] / horizontal];
  else { const d = direction(az, 0); toward = [d[0], d[1]]; }
  gl.uniform3fv(uniforms.uView, view);
  gl.uniform2f(uniforms.uToward, toward[0], toward[1]);
  gl.uniform2f(uniforms.uRight, toward[1], -toward[0]);
  gl.uniform1f(uniforms.uStretch, 1 / view[2]);
  gl.uniform1f(uniforms.uDepth, bakeScale[m.id] || (state ? state.params.scale : 1));
  const basis = bakeBasis[m.id];
  if (basis && basis.length === 3) gl.uniform3fv(uniforms.uBasis, basis.flat());
  gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
  gl.finish();
  document.body.dataset.drawnBake = String(m.id);
  document.body.dataset.drawnAt = String(Date.now());
}

// For tests: a checksum and the mean of the drawn pixels.
window.bbCanvasStats = function () {
  const w = canvas.width, h = canvas.height, px = new Uint8Array(4 * w * h);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  let sum = 0, hash = 2166136261;
  for (let i = 0; i < px.length; i += 4) {
    sum += px[i] + px[i + 1] + px[i + 2];
    hash = Math.imul(hash ^ px[i] ^ (px[i + 1] << 8) ^ (px[i + 2] << 16), 16777619) >>> 0;
  }
  return { mean: sum / (3 * w * h), hash: hash };
};

// ---------------------------------------------------------------- state

// The library's range of an input as its min and max: a bottom the range
// leaves out ("scale > 0") is no HTML min, which would let it in.
function bound(input, r) {
  if (!r) return;
  if (r.min !== undefined && !r.min_exclusive) input.min = String(r.min);
  if (r.max !== undefined) input.max = String(r.max);
}

// The input of a control, by its row's type: a number box (its range as
// min and max, but no min above the value the option holds unset, which
// the control goes back to: slices 0, "from rays"), a box of several
// numbers or of text, a list of words, a check box for a flag and for a
// file option (on: the file serve was given).
function controlInput(c) {
  let input;
  if (c.type === "integer" || c.type === "number") {
    input = document.createElement("input");
    input.type = "number";
    input.step = c.type === "integer" ? "1" : "any";
    const unset = Number(c.unset);
    bound(input, { min: c.min !== undefined && unset < c.min ? undefined : c.min,
                   max: c.max, min_exclusive: c.min_exclusive });
  } else if (c.type === "word") {
    input = document.createElement("select");
    for (const word of c.value_name.split("|")) input.add(new Option(word, word));
  } else if (c.type === "flag" || c.type === "path") {
    input = document.createElement("input");
    input.type = "checkbox";
  } else {
    input = document.createElement("input");
    input.type = "text";
    input.size = 11;
  }
  input.id = "p-" + c.name;
  const more = [c.default && "default " + c.default, c.range && "range " + c.range];
  input.title = "--" + c.name + (c.value_name && c.type !== "word" ? " " + c.value_name : "") +
                ": " + c.help + (more.some(Boolean) ? " (" + more.filter(Boolean).join("; ") + ")" : "");
  return input;
}

function isSwitch(c) {
  return c.type === "flag" || c.type === "path";
}

// Each control in its place ("bake" or "light"), labelled by its option.
function buildControls() {
  for (const c of controls) {
    const input = controlInput(c), label = document.createElement("label");
    label.id = "label-" + c.name;
    if (isSwitch(c)) {
      const file = document.createElement("span");
      file.id = "file-" + c.name;
      label.append(input, " " + c.name + " ", file);
    } else {
      label.append(c.name + " ", input);
    }
    $("controls-" + c.place).appendChild(label);
    input.addEventListener("change", () => sendControls(c.place));
  }
}

// A control's value as the state holds it, as its input shows it.
function showControl(c, s) {
  const input = $("p-" + c.name), value = s.params[c.key];
  if (c.type === "path") {
    const file = s.params[c.key + "_file"];
    $("label-" + c.name).style.display = file ? "" : "none";
    $("file-" + c.name).textContent = file ? "(" + file + ")" : "";
  }
  if (isSwitch(c)) input.checked = !!value;
  else if (document.activeElement !== input)
    input.value = Array.isArray(value) ? value.join(",") : String(value);
}

// The value a control sends: a file option "on" or "off", a flag 1 or 0.
function controlValue(c) {
  const input = $("p-" + c.name);
  if (c.type === "path") return input.checked ? "on" : "off";
  if (c.type === "flag") return input.checked ? "1" : "0";
  return input.value;
}

// Why the picture is not the maps of now, or "" when it is.
function staleReason(s) {
  if (!s || !current) return "";
  const of = "the picture is bake " + shown().id + "'s";
  if (s.baking)
    return "baking: " + (s.stage || "starting") + ", " + Math.round(100 * s.progress) + "%; " + of;
  if (s.pending) return "a bake is waiting to start; " + of;
  if (s.error) return s.error + "\n" + of + ", the last that baked";
  if (s.bake && s.bake.id > current.id) return "loading bake " + s.bake.id + "; " + of;
  if (showB && previous) return "B: bake " + previous.id + ", the one before the last";
  return "";
}

function showStale() {
  const why = staleReason(state);
  $("view").classList.toggle("stale", why !== "" && !(showB && previous && !state.baking &&
                                                       !state.pending && !state.error));
  $("stale").textContent = why;
}

// The view's controls where they apply: the light (its colour, the colour
// map) in the lit modes, the camera in relief.
function showControls() {
  const mode = Number($("mode").value), lit = LIT_MODES.includes(mode);
  $("light-controls").classList.toggle("hidden", !lit);
  $("light-readout").classList.toggle("hidden", !lit);
  $("view-controls").classList.toggle("hidden", mode !== RELIEF_MODE);
  $("albedo-label").classList.toggle("hidden", !(state && state.params.albedo_file));
}

// The command line, its words kept whole on a line (a word longer than
// the line breaks where it must): a box per word, the blanks between them
// (copied as they are).
function showCommand(line) {
  const el = $("command");
  if (el.dataset.line === line) return;
  el.dataset.line = line;
  el.textContent = "";
  line.split(" ").forEach((word, i) => {
    if (i) el.appendChild(document.createTextNode(" "));
    const span = document.createElement("span");
    span.className = "word";
    span.textContent = word;
    el.appendChild(span);
  });
}

function showState(s) {
  state = s;
  $("height").textContent = s.height;
  showCommand(s.command);
  $("progress").value = s.baking ? s.progress : (s.bake ? 1 : 0);
  $("status").textContent = s.baking ? "baking: " + (s.stage || "starting") + ", " +
                                       Math.round(100 * s.progress) + "%"
                                     : (s.bake ? "bake " + s.bake.id + " shown" : "no bake yet");
  $("error").textContent = s.error ? s.error + " (the last good maps stay shown)" : "";
  for (const c of controls) showControl(c, s);
  $("albedo-name").textContent = s.params.albedo_file ? "(" + s.params.albedo_file + ")" : "";
  if (s.bake) {
    const b = s.bake;
    bakeScale[b.id] = b.scale;
    bakeBasis[b.id] = b.basis_vectors;
    showBasis(b);
    $("times").textContent = `${b.width} x ${b.height}, ${b.slices} slices, ${b.threads} threads: ` +
      `${b.seconds.toFixed(3)} s (load ${b.seconds_load.toFixed(3)}, smooth ${b.seconds_smooth.toFixed(3)}, ` +
      `pyramid ${b.seconds_pyramid.toFixed(3)}, trace ${b.seconds_trace.toFixed(3)}, ` +
      (b.seconds_bounce > 0 ? `bounce ${b.seconds_bounce.toFixed(3)}, ` : "") +
      `derive ${b.seconds_derive.toFixed(3)})`;
    $("provenance").textContent = b.provenance;
    if ((!current || b.id > current.id) && !loading) loadMaps().catch((e) => fail(String(e)));
  }
  showControls();
  showStale();
  // Drawn again only when what the picture reads from the state changed:
  // a bake's progress, ten times a second, would draw the same picture
  // (a SwiftShader draw is CPU the bake needs).
  const inputs = JSON.stringify([s.params.light_color, s.params.albedo_file, s.params.scale,
                                 s.bake ? s.bake.normal_y_up : null]);
  if (inputs !== drawnFrom) {
    drawnFrom = inputs;
    requestDraw();
  }
}

// The ssbump's lit modes take the bake's 3 basis directions; a basis of
// more does not fit the page's ssbump texture (3 channels and ao): those
// modes are turned off, saying why, rather than lit wrongly.
function showBasis(b) {
  const lit = b.basis_count === 3;
  const v = (x) => "(" + x.map((c) => c.toFixed(3)).join(", ") + ")";
  $("basis-note").textContent = lit
    ? "ssbump lit in the bake's basis " + b.basis + (b.basis === "hl2" ? " (Half-Life 2's)" :
      ": " + b.basis_vectors.map(v).join(" "))
    : "basis " + b.basis + " has " + b.basis_count + " directions: the page lights an " +
      "ssbump of 3 (its texture holds 3), so \"ssbump, lit\" and relief are off; " +
      "\"ssbump map\" and \"basis weights\" show the first 3 channels";
  for (const m of SSBUMP_MODES)
    document.querySelector('#mode option[value="' + m + '"]').disabled = !lit;
  if (!lit && SSBUMP_MODES.includes(Number($("mode").value))) $("mode").value = "1";
}

async function post(path) {
  const r = await fetch(path, { method: "POST", headers: { "X-Bumpbake": "1" } });
  const body = await r.json();
  if (!r.ok) throw new Error(body.error || r.statusText);
  return body;
}

async function sendParams(query) {
  $("controls-error").textContent = "";
  try {
    showState(await post("params?" + query.join("&")));
  } catch (e) {
    $("controls-error").textContent = e.message;  // the library's words
  }
}

// The controls of a place, all at once, each by its option's name: the
// library parses and checks them (a file option only when serve was
// given its file).
function sendControls(place) {
  const query = controls.filter((c) => c.place === place &&
                                       (c.type !== "path" || (state && state.params[c.key + "_file"])))
    .map((c) => c.name + "=" + encodeURIComponent(controlValue(c)));
  sendParams(query);
}

$("mode").addEventListener("input", () => {
  showControls();
  const m = current, need = texturesOf(Number($("mode").value));
  if (m && m.whole && need.some((t) => !m.tex[t]) && !loading) {
    current = null;  // not all of it here yet: the bake shown again, whole
    freeMaps(m);
    loadMaps().catch((e) => fail(String(e)));
  }
  requestDraw();
});
$("tile").addEventListener("input", () => { showZoom(); requestDraw(); });
$("albedo").addEventListener("input", requestDraw);
for (const id of ["view-az", "view-el"]) {
  $(id).addEventListener("input", requestDraw);
  $(id).addEventListener("change", () => {
    viewValue($("view-az"), null, 270, true);
    viewValue($("view-el"), ranges.view_elevation, 30, true);
    requestDraw();
  });
}

$("write").addEventListener("click", async () => {
  $("write-result").textContent = "";
  $("write-error").textContent = "";
  try {
    const r = await post("write");
    $("write-result").textContent = "wrote " + r.outputs.map((o) => o.path).join(", ") +
      (r.from === "memory" ? " (the maps shown, not baked again)" : " (baked again: " + r.reason + ")");
  } catch (e) {
    $("write-error").textContent = e.message;
  }
});

showLight();
showControls();
setup().then(() => {
  const events = new EventSource("events");
  events.onmessage = (e) => showState(JSON.parse(e.data));
}).catch((e) => fail(String(e)));

// serve.js: the page of `bumpbake serve`. It follows the server's state
// through server-sent events ("events"), fetches the textures of each new
// bake ("map/NAME": 8-bit RGBA, X-Bake-Id saying which bake), draws them
// with WebGL 2 (serve.frag.glsl after shaders/ssbump_relief.glsl), relights
// as the light is dragged, and sends the controls ("params") and the write
// action ("write"). The inputs' ranges are the library's ("ranges": the
// options' descriptions), none of the page's own. Once a bake's maps are
// drawn, <body data-drawn-bake> holds its id and data-drawn-at the time
// (Date.now()), for tests.
"use strict";

const $ = (id) => document.getElementById(id);
const canvas = $("canvas");
const gl = canvas.getContext("webgl2", { preserveDrawingBuffer: true, antialias: false });
const TEXTURES = ["ssbump_ao", "normal_height", "bent", "weights"];
const light = { azimuth: 135, elevation: 45 };  // render's default light
let program = null, uniforms = {}, textures = {}, heightTexture = null;
let maps = null;          // {id, width, height} of the textures loaded
let state = null;         // the server's last state
let loading = 0;          // the bake id being fetched, 0 when none
let drawPending = false;
const bakeScale = {};      // each bake's --scale by id: the depth of its relief
const bakeBasis = {};      // each bake's basis directions by id: the ssbump's lighting
const SSBUMP_MODES = [0, 8];  // the modes that light the ssbump with the basis
let ranges = {};          // the server's "ranges": {name: {min, max, min_exclusive}}

function fail(message) {
  $("error").textContent = message;
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

canvas.addEventListener("pointerdown", (e) => {
  canvas.setPointerCapture(e.pointerId);
  dragLight(e);
});
canvas.addEventListener("pointermove", (e) => {
  if (e.buttons) dragLight(e);
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
    ["ssbump_relief.glsl", "serve.frag.glsl", "ranges"].map((f) => fetch(f).then(
      (r) => f === "ranges" ? r.json() : r.text())));
  ranges = got;
  showRanges();
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
  ["uSsbumpAo", "uNormalHeight", "uBent", "uWeights", "uHeight"].forEach((name, unit) => {
    gl.uniform1i(uniforms[name], unit);
  });
}

function makeTexture(unit) {
  const t = gl.createTexture();
  gl.activeTexture(gl.TEXTURE0 + unit);
  gl.bindTexture(gl.TEXTURE_2D, t);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);  // the maps tile
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.REPEAT);
  return t;
}

function upload(unit, internal, format, w, h, bytes) {
  gl.activeTexture(gl.TEXTURE0 + unit);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, gl.UNSIGNED_BYTE, bytes);
}

// The textures each mode reads (serve.frag.glsl); the height texture is
// made from normal_height's alpha.
function texturesOf(mode) {
  return { 0: ["ssbump_ao"], 3: ["ssbump_ao"], 6: ["ssbump_ao"], 4: ["bent"], 5: ["weights"] }[mode]
         || ["ssbump_ao", "normal_height"];
}

// Fetches names of the last good bake; they must all be of one bake (id,
// or any when id is 0). Returns {id, w, h, data} or null when a newer bake
// landed in between.
async function fetchMaps(names, id) {
  const replies = await Promise.all(names.map((name) => fetch("map/" + name)));
  for (const r of replies)
    if (!r.ok) throw new Error("map: " + r.status + " " + (await r.text()));
  const ids = replies.map((r) => Number(r.headers.get("X-Bake-Id")));
  const data = await Promise.all(replies.map((r) => r.arrayBuffer()));
  if (ids.some((x) => x !== ids[0]) || (id && ids[0] !== id)) return null;
  return { id: ids[0], w: Number(replies[0].headers.get("X-Width")),
           h: Number(replies[0].headers.get("X-Height")), data: data };
}

function uploadMaps(names, got) {
  names.forEach((name, i) => {
    const unit = TEXTURES.indexOf(name);
    if (!textures[name]) textures[name] = makeTexture(unit);
    upload(unit, gl.RGBA8, gl.RGBA, got.w, got.h, new Uint8Array(got.data[i]));
    if (name === "normal_height") {
      // the relief reads the height's first channel (ssbump_relief.glsl's relief_h)
      const nh = new Uint8Array(got.data[i]), n = got.w * got.h, height = new Uint8Array(n);
      for (let k = 0; k < n; k++) height[k] = nh[4 * k + 3];
      if (!heightTexture) heightTexture = makeTexture(4);
      upload(4, gl.R8, gl.RED, got.w, got.h, height);
    }
  });
}

// A new bake: first the textures the picture shown needs, drawn at once,
// then the others (so a save shows as soon as its ssbump has arrived).
async function loadMaps() {
  loading = 1;
  try {
    for (;;) {
      const first = texturesOf(Number($("mode").value));
      const got = await fetchMaps(first, 0);
      if (!got) continue;  // a bake landed in between: again
      const rest = TEXTURES.filter((t) => !first.includes(t));
      uploadMaps(first, got);
      maps = { id: got.id, width: got.w, height: got.h };
      fitCanvas();
      draw();
      const others = await fetchMaps(rest, got.id);
      if (others) uploadMaps(rest, others);
      else continue;  // newer maps already: load them whole
      draw();
      break;
    }
  } finally {
    loading = 0;
  }
  if (state && state.bake && state.bake.id > maps.id) loadMaps();
}

// The picture keeps the maps' shape, its longer side 640 pixels.
function fitCanvas() {
  const tall = maps.height > maps.width;
  const w = tall ? Math.round(640 * maps.width / maps.height) : 640;
  const h = tall ? 640 : Math.round(640 * maps.height / maps.width);
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
    canvas.style.width = w + "px";
    canvas.style.height = h + "px";
  }
}

function requestDraw() {
  if (drawPending || !maps) return;
  drawPending = true;
  requestAnimationFrame(() => { drawPending = false; draw(); });
}

function draw() {
  if (!maps) return;
  const mode = Number($("mode").value), tile = $("tile").checked ? 2 : 1;
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.uniform2f(uniforms.uSize, maps.width, maps.height);
  gl.uniform2f(uniforms.uCanvas, canvas.width, canvas.height);
  gl.uniform1f(uniforms.uTile, tile);
  gl.uniform1i(uniforms.uMode, mode);
  gl.uniform3fv(uniforms.uLight, direction(light.azimuth, light.elevation));
  gl.uniform1f(uniforms.uNormalYUp, state && state.bake && state.bake.normal_y_up ? 1 : 0);
  // render's camera (job_init): towards it, the screen's right, the stretch
  const el = clamp(Number($("view-el").value) || 30, ranges.view_elevation);
  const view = direction(Number($("view-az").value) || 0, el);
  let toward = [view[0], view[1]];
  const horizontal = Math.hypot(view[0], view[1]);
  if (horizontal > 1e-9) toward = [view[0] / horizontal, view[1] / horizontal];
  else { const d = direction(Number($("view-az").value) || 0, 0); toward = [d[0], d[1]]; }
  gl.uniform3fv(uniforms.uView, view);
  gl.uniform2f(uniforms.uToward, toward[0], toward[1]);
  gl.uniform2f(uniforms.uRight, toward[1], -toward[0]);
  gl.uniform1f(uniforms.uStretch, 1 / view[2]);
  gl.uniform1f(uniforms.uDepth, bakeScale[maps.id] || (state ? state.params.scale : 1));
  const basis = bakeBasis[maps.id];
  if (basis && basis.length === 3) gl.uniform3fv(uniforms.uBasis, basis.flat());
  gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
  gl.finish();
  document.body.dataset.drawnBake = String(maps.id);
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

const PARAMS = ["scale", "rays", "slices", "bias", "bounce", "bounces"];

// The library's range of an input as its min and max: a bottom the range
// leaves out ("scale > 0") is no HTML min, which would let it in.
function bound(input, r) {
  if (!r) return;
  if (r.min !== undefined && !r.min_exclusive) input.min = String(r.min);
  if (r.max !== undefined) input.max = String(r.max);
}

function showRanges() {
  for (const p of PARAMS) {
    // slices 0 is "from rays" (a bake's slices 0), below --slices's range
    bound($("p-" + p), p === "slices" ? { max: ranges[p] && ranges[p].max } : ranges[p]);
  }
  bound($("view-el"), ranges.view_elevation);
}

function showState(s) {
  state = s;
  $("height").textContent = s.height;
  $("command").textContent = s.command;
  $("progress").value = s.baking ? s.progress : (s.bake ? 1 : 0);
  $("status").textContent = s.baking ? "baking... " + Math.round(100 * s.progress) + "%"
                                     : (s.bake ? "bake " + s.bake.id + " shown" : "no bake yet");
  $("error").textContent = s.error ? s.error + " (the last good maps stay shown)" : "";
  for (const p of PARAMS) {
    const input = $("p-" + p);
    if (document.activeElement !== input) input.value = s.params[p];
  }
  $("brightness-label").style.display = s.params.brightness_file ? "" : "none";
  $("p-brightness").checked = s.params.brightness;
  if (s.bake) {
    const b = s.bake;
    bakeScale[b.id] = b.scale;
    bakeBasis[b.id] = b.basis_vectors;
    showBasis(b);
    $("times").textContent = `${b.width} x ${b.height}, ${b.slices} slices, ${b.threads} threads: ` +
      `${b.seconds.toFixed(3)} s (load ${b.seconds_load.toFixed(3)}, smooth ${b.seconds_smooth.toFixed(3)}, ` +
      `pyramid ${b.seconds_pyramid.toFixed(3)}, trace ${b.seconds_trace.toFixed(3)}, ` +
      `derive ${b.seconds_derive.toFixed(3)})`;
    $("provenance").textContent = b.provenance;
    if ((!maps || b.id > maps.id) && !loading) loadMaps().catch((e) => fail(String(e)));
  }
  requestDraw();
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

async function sendParams() {
  const query = PARAMS.map((p) => p + "=" + encodeURIComponent($("p-" + p).value));
  if (state && state.params.brightness_file)
    query.push("brightness=" + ($("p-brightness").checked ? "on" : "off"));
  $("controls-error").textContent = "";
  try {
    showState(await post("params?" + query.join("&")));
  } catch (e) {
    $("controls-error").textContent = e.message;  // the library's words
  }
}

for (const p of PARAMS) $("p-" + p).addEventListener("change", sendParams);
$("p-brightness").addEventListener("change", sendParams);
for (const id of ["mode", "tile", "view-az", "view-el"]) $(id).addEventListener("input", requestDraw);

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
setup().then(() => {
  const events = new EventSource("events");
  events.onmessage = (e) => showState(JSON.parse(e.data));
}).catch((e) => fail(String(e)));

// atmos sky viewer: WebGL2 rendering of baked tables with the model's GLSL
// (DIR/MODEL/shaders/, embedded in MODEL/model.js), plain JavaScript.
// Written by `atmos viewer`; the source is viewer/viewer.js in the repository.
'use strict';

// ---- small vector helpers (double precision, as the C++ camera) ----
function vAdd(a, b) { return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]; }
function vScale(a, s) { return [a[0] * s, a[1] * s, a[2] * s]; }
function vDot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
function vCross(a, b) {
  return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
}
function vNormalize(a) { return vScale(a, 1 / Math.sqrt(vDot(a, a))); }
function radians(d) { return d * Math.PI / 180; }

// MakeCamera (src/atmos/harness/views.cpp).
function makeCamera(position, forward, worldUp, vfovDeg) {
  var f = vNormalize(forward);
  var right = vNormalize(vCross(f, worldUp));
  var up = vCross(right, f);
  return {position: position, forward: f, right: right, up: up,
          tanHalfFovY: Math.tan(radians(vfovDeg) * 0.5), vfov: vfovDeg};
}
// AzimuthElevation (views.cpp).
function azimuthElevation(azDeg, elDeg) {
  var a = radians(azDeg), e = radians(elDeg);
  return [Math.cos(e) * Math.cos(a), Math.cos(e) * Math.sin(a), Math.sin(e)];
}

// StandardViews (src/atmos/harness/views.cpp; docs/views.md): the 12 views
// for an atmosphere of radii R (bottom) and top.
function standardViews(R, top) {
  var z = [0, 0, 1];
  var views = [];
  var times = [['dawn', -6, 16], ['sunrise', 6, 1], ['noon', 90, 1]];
  [['ground', 0], ['plane', 5000]].forEach(function (place) {
    times.forEach(function (t) {
      views.push({name: place[0] + '-' + t[0],
                  camera: makeCamera([0, 0, R + place[1]], azimuthElevation(0, 10), z, 60),
                  sun: azimuthElevation(0, t[1]), exposure: t[2]});
    });
  });
  times.forEach(function (t) {
    views.push({name: 'orbit-' + t[0],
                camera: makeCamera([-1000e3, 0, R + 100e3], [1, 0, 0], z, 60),
                sun: azimuthElevation(0, t[1]), exposure: t[2]});
  });
  var d = 3.75 * top;
  views.push({name: 'space', camera: makeCamera([0, -d, 0], [0, 1, 0], z, 40),
              sun: vNormalize([0.8, -0.3, 0.5]), exposure: 2});
  views.push({name: 'planet-shadow-ground',
              camera: makeCamera([0, 0, R], azimuthElevation(150, 10), z, 60),
              sun: azimuthElevation(0, -3), exposure: 32});
  views.push({name: 'planet-shadow-orbit',
              camera: makeCamera([0, 0, R + 200e3], azimuthElevation(150, -12), z, 60),
              sun: azimuthElevation(0, -3), exposure: 32});
  return views;
}

// ---- tables ----
function encodeBase64(buffer) {
  var bytes = new Uint8Array(buffer);
  var parts = [];
  for (var i = 0; i < bytes.length; i += 0x8000) {
    parts.push(String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000)));
  }
  return btoa(parts.join(''));
}

// Loads MODEL/tables.f32 (the one copy of the bake's tables, issue 35) for
// each model; done(blobs) or fail(message). Asynchronous, except in the test
// and benchmark modes (`sync`): headless Chromium's --dump-dom writes the DOM
// at the load event, which an asynchronous request does not hold back.
function loadTables(names, sync, done, failOnce) {
  var blobs = {}, left = names.length, failed = false;
  var fail = function (msg) { if (!failed) { failed = true; failOnce(msg); } };
  function refused(name, why) {
    var msg = 'cannot read ' + name + '/tables.f32 (' + why + ')';
    if (window.location.protocol === 'file:') {
      msg += ': browsers refuse to read files from a file:// page. Serve the folder, e.g. ' +
             '`python3 -m http.server -d DIR 8000` and open http://localhost:8000/, or start ' +
             'Chromium with --allow-file-access-from-files';
    }
    return msg;
  }
  if (left === 0) { done(blobs); return; }
  names.forEach(function (name) {
    var url = name + '/tables.f32';
    var x = new XMLHttpRequest();
    var ok = function () { return x.status === 200 || (x.status === 0 && x.response !== null); };
    if (sync) {
      // A synchronous request cannot ask for an ArrayBuffer: bytes as text.
      x.open('GET', url, false);
      x.overrideMimeType('text/plain; charset=x-user-defined');
      try { x.send(); } catch (e) { fail(refused(name, String(e.message || e))); return; }
      if (!ok()) { fail(refused(name, 'status ' + x.status)); return; }
      var text = x.responseText;
      var bytes = new Uint8Array(text.length);
      for (var i = 0; i < text.length; ++i) bytes[i] = text.charCodeAt(i) & 0xff;
      blobs[name] = bytes.buffer;
      if (--left === 0) done(blobs);
      return;
    }
    x.open('GET', url, true);
    x.responseType = 'arraybuffer';
    x.onload = function () {
      if (!ok()) { fail(refused(name, 'status ' + x.status)); return; }
      blobs[name] = x.response;
      if (--left === 0) done(blobs);
    };
    x.onerror = function () { fail(refused(name, 'request failed')); };
    try { x.send(); } catch (e) { fail(refused(name, String(e.message || e))); }
  });
}

// A texture from the bake's float32 blob: "raw" -> tables -> NAME gives sizes
// and offsets (src/atmos/io/raw_tables.h). format 'f16': uploaded into a
// float16 texture (WebGL2 converts float data; filterable everywhere).
function makeTexture(gl, blob, format, entry) {
  var half = format === 'f16';
  var data = new Float32Array(blob, entry.float32_offset, entry.values);
  var c = entry.channels;
  var internal = c === 4 ? (half ? gl.RGBA16F : gl.RGBA32F) : (half ? gl.RGB16F : gl.RGB32F);
  var fmt = c === 4 ? gl.RGBA : gl.RGB;
  var type = gl.FLOAT;
  var is3d = entry.depth > 1;
  var target = is3d ? gl.TEXTURE_3D : gl.TEXTURE_2D;
  var tex = gl.createTexture();
  gl.bindTexture(target, tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  if (is3d) {
    gl.texImage3D(target, 0, internal, entry.width, entry.height, entry.depth, 0, fmt, type, data);
  } else {
    gl.texImage2D(target, 0, internal, entry.width, entry.height, 0, fmt, type, data);
  }
  gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
  gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
  gl.texParameteri(target, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(target, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  if (is3d) gl.texParameteri(target, gl.TEXTURE_WRAP_R, gl.CLAMP_TO_EDGE);
  return {texture: tex, target: target};
}

// ---- shaders ----
var VERTEX_SHADER = [
  '#version 300 es',
  'void main() {',
  '  // One triangle covering the viewport.',
  '  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));',
  '  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);',
  '}'].join('\n');

// The per-pixel part of `atmos render` (ShadePixel, src/atmos/render/render.h)
// over the model's atmos_Evaluate: the ray of Camera::RayDirection through the
// pixel centre, (sky + ground) x irradiance, the optional sun disc; raw
// radiance (u_raw) or exposure, 1 - exp(-x) and the sRGB curve (as PNG output).
var MAIN_SHADER = [
  'uniform vec3 u_camera;',
  'uniform vec3 u_forward;',
  'uniform vec3 u_right;',
  'uniform vec3 u_up;',
  'uniform float u_tan_half_fov_y;',
  'uniform vec2 u_size;',
  'uniform vec3 u_sun;',
  'uniform float u_sun_irradiance;',
  'uniform float u_exposure;',
  'uniform bool u_raw;',
  'uniform bool u_sun_disc;',
  'out vec4 frag_color;',
  'float srgb(float c) { return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055; }',
  'void main() {',
  '  vec2 p = gl_FragCoord.xy;  // y up: image row (height - p.y)',
  '  float aspect = u_size.x / u_size.y;',
  '  float u = (2.0 * p.x / u_size.x - 1.0) * u_tan_half_fov_y * aspect;',
  '  float v = (2.0 * p.y / u_size.y - 1.0) * u_tan_half_fov_y;',
  '  vec3 dir = normalize(u_forward + u_right * u + u_up * v);',
  '  vec3 sky, ground, transmittance;',
  '  bool hits_ground;',
  '  atmos_Evaluate(u_camera, dir, u_sun, sky, ground, transmittance, hits_ground);',
  '  vec3 irradiance = ATMOS_SOLAR_IRRADIANCE * u_sun_irradiance;',
  '  vec3 radiance = (sky + ground) * irradiance;',
  '  if (u_sun_disc && !hits_ground && dot(dir, u_sun) >= cos(ATMOS_SUN_ANGULAR_RADIUS)) {',
  '    radiance += irradiance * transmittance /',
  '                (ATMOS_PI * ATMOS_SUN_ANGULAR_RADIUS * ATMOS_SUN_ANGULAR_RADIUS);',
  '  }',
  '  radiance = max(radiance, vec3(0.0));',
  '  if (u_raw) { frag_color = vec4(radiance, 1.0); return; }',
  '  vec3 c = 1.0 - exp(-radiance * u_exposure);',
  '  frag_color = vec4(srgb(c.r), srgb(c.g), srgb(c.b), 1.0);',
  '}'].join('\n');

function compile(gl, type, source) {
  var s = gl.createShader(type);
  gl.shaderSource(s, source);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) {
    throw new Error('shader compile error: ' + gl.getShaderInfoLog(s));
  }
  return s;
}

var GLSL_HEADER = '#version 300 es\nprecision highp float;\nprecision highp sampler2D;\n' +
                  'precision highp sampler3D;\n';

// Which sampler reads which baked table ("raw" table name).
var BAKED_SAMPLERS = [['atmos_transmittance_texture', 'transmittance'],
                      ['atmos_irradiance_texture', 'irradiance'],
                      ['atmos_scattering_texture', 'scattering'],
                      ['atmos_single_mie_texture', 'single_mie_scattering'],
                      ['atmos_multiple_scattering_texture', 'multiple_scattering']];

// One model: its program (GLSL ES header + the bake's constants + common.glsl
// and the model's functions + MAIN_SHADER) and its textures. The baked
// tables' textures stay in model.bakedTextures; a GPU precomputation
// (runPrecompute) puts its targets in their units of model.textures.
function makeModel(gl, name, format, blob) {
  var data = atmosViewerData.models[name];
  // A model without tables (hosek-wilkie: constants only) has an empty blob.
  if (!data || blob === undefined) throw new Error('no baked data for model ' + name);
  var raw = data.bake.raw.tables;
  // Texture units: every baked table a sampler of the shaders reads, in this
  // order (the sampler names of shaders/*.glsl, docs/engine.md; the same list
  // as examples/gl_host's): asked of the bake's tables, not of the model's
  // name.
  var samplers = BAKED_SAMPLERS;
  var atm = data.bake.atmosphere;
  var model = {name: name, data: data, textures: [], units: [], tableUnit: {},
               bottom: atm.bottom_radius, top: atm.top_radius};
  samplers.forEach(function (s) {
    if (!raw[s[1]]) return;
    model.tableUnit[s[1]] = model.textures.length;
    model.units.push([s[0], model.textures.length]);
    model.textures.push(makeTexture(gl, blob, format, raw[s[1]]));
  });
  model.bakedTextures = model.textures.slice();
  // The per-frame passes, for a shader that defines them (asked of the
  // shader, as src/atmos/io/engine_shaders.h does).
  if (data.functions.indexOf('atmos_SkyViewTexel') >= 0) makeHillaireFrame(gl, model);
  linkModel(gl, model, data.constants);
  return model;
}

// (Re)links the model's programs over the constants `constants` (the bake's,
// or those of another atmosphere: atmosphereConstants).
function linkModel(gl, model, constants) {
  var base = GLSL_HEADER + constants + '\n' + model.data.functions + '\n';
  model.program = linkProgram(gl, base + MAIN_SHADER);
  gl.useProgram(model.program);
  model.units.forEach(function (u) {
    gl.uniform1i(gl.getUniformLocation(model.program, u[0]), u[1]);
  });
  if (model.hillaire) linkHillaireFrame(gl, model, base);
  model.constants = constants;
}

// Hillaire's per-frame tables (hillaire.glsl, passes 1 and 2): the sky-view
// table (192 x 108) and the aerial-perspective volume (32^3, in-scatter and
// transmittance, one pass per slice marching on from the previous slice),
// float render targets sampled by the main pass.
var SKY_VIEW_MAIN = [
  'uniform float u_r;',
  'uniform vec3 u_sun;',
  'out vec4 frag_color;',
  'void main() {',
  '  frag_color = vec4(atmos_SkyViewTexel(ivec2(gl_FragCoord.xy), u_r, u_sun), 1.0);',
  '}'].join('\n');
// One slice of the aerial-perspective volume: froxel (x, y, u_slice) continues
// slice u_slice - 1's L, T (a 32 x 32 copy of the previous slice, ping-pong)
// and writes the volume's layer and the copy for the next slice.
var AP_MAIN = [
  'uniform int u_slice;',
  'uniform vec3 u_camera;',
  'uniform vec3 u_sun;',
  'uniform highp sampler2D u_prev_scatter;',
  'uniform highp sampler2D u_prev_transmittance;',
  'layout(location = 0) out vec4 frag_scatter;',
  'layout(location = 1) out vec4 frag_transmittance;',
  'layout(location = 2) out vec4 next_scatter;',
  'layout(location = 3) out vec4 next_transmittance;',
  'void main() {',
  '  ivec2 p = ivec2(gl_FragCoord.xy);',
  '  vec3 L = vec3(0.0), T = vec3(1.0);',
  '  if (u_slice > 0) {',
  '    L = texelFetch(u_prev_scatter, p, 0).rgb;',
  '    T = texelFetch(u_prev_transmittance, p, 0).rgb;',
  '  }',
  '  atmos_AerialPerspectiveStep(ivec3(p, u_slice), u_camera, u_sun, L, T);',
  '  frag_scatter = vec4(L, 1.0);',
  '  frag_transmittance = vec4(T, 1.0);',
  '  next_scatter = frag_scatter;',
  '  next_transmittance = frag_transmittance;',
  '}'].join('\n');

function linkProgram(gl, fragment) {
  var program = gl.createProgram();
  gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, VERTEX_SHADER));
  gl.attachShader(program, compile(gl, gl.FRAGMENT_SHADER, fragment));
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) {
    throw new Error('link error: ' + gl.getProgramInfoLog(program));
  }
  return program;
}

function makeTarget(gl, target, w, h, d) {
  var internal = gl.getExtension('OES_texture_float_linear') ? gl.RGBA32F : gl.RGBA16F;
  var tex = gl.createTexture();
  gl.bindTexture(target, tex);
  if (target === gl.TEXTURE_3D) {
    gl.texStorage3D(target, 1, internal, w, h, d);
    gl.texParameteri(target, gl.TEXTURE_WRAP_R, gl.CLAMP_TO_EDGE);
  } else {
    gl.texStorage2D(target, 1, internal, w, h);
  }
  gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
  gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
  gl.texParameteri(target, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(target, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  return {texture: tex, target: target};
}

function makeHillaireFrame(gl, model) {
  if (!gl.getExtension('EXT_color_buffer_float')) {
    throw new Error('hillaire needs EXT_color_buffer_float (float render targets)');
  }
  var sky = makeTarget(gl, gl.TEXTURE_2D, 192, 108, 1);
  var apS = makeTarget(gl, gl.TEXTURE_3D, 32, 32, 32);
  var apT = makeTarget(gl, gl.TEXTURE_3D, 32, 32, 32);
  [['atmos_sky_view_texture', sky], ['atmos_ap_scatter_texture', apS],
   ['atmos_ap_transmittance_texture', apT]].forEach(function (u) {
    model.units.push([u[0], model.textures.length]);
    model.textures.push(u[1]);
  });
  // Ping-pong copies of one slice's L and T for the next slice.
  var state = [0, 1].map(function () {
    return [makeTarget(gl, gl.TEXTURE_2D, 32, 32, 1), makeTarget(gl, gl.TEXTURE_2D, 32, 32, 1)];
  });
  model.hillaire = {skyTarget: sky, apScatter: apS, apTransmittance: apT, apState: state,
                    skyFb: gl.createFramebuffer(), apFb: gl.createFramebuffer()};
  gl.bindFramebuffer(gl.FRAMEBUFFER, model.hillaire.skyFb);
  gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, sky.texture, 0);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
}
function linkHillaireFrame(gl, model, base) {
  var passes = model.hillaire;
  passes.sky = linkProgram(gl, base + SKY_VIEW_MAIN);
  passes.ap = linkProgram(gl, base + AP_MAIN);
  // The baked tables at the model's units (not the frame's own targets), the
  // previous slice after every unit.
  [passes.sky, passes.ap].forEach(function (p) {
    gl.useProgram(p);
    model.units.slice(0, model.bakedTextures.length).forEach(function (u) {
      gl.uniform1i(gl.getUniformLocation(p, u[0]), u[1]);
    });
  });
  passes.prevUnit = model.units.length;
  gl.uniform1i(gl.getUniformLocation(passes.ap, 'u_prev_scatter'), passes.prevUnit);
  gl.uniform1i(gl.getUniformLocation(passes.ap, 'u_prev_transmittance'), passes.prevUnit + 1);
}

// The frame camera of Hillaire's aerial-perspective volume (atmos_ap_*).
function setApCamera(gl, program, c, aspect) {
  gl.uniform3fv(gl.getUniformLocation(program, 'atmos_ap_forward'), c.forward);
  gl.uniform3fv(gl.getUniformLocation(program, 'atmos_ap_right'), c.right);
  gl.uniform3fv(gl.getUniformLocation(program, 'atmos_ap_up'), c.up);
  gl.uniform1f(gl.getUniformLocation(program, 'atmos_ap_tan_half_fov_y'), c.tanHalfFovY);
  gl.uniform1f(gl.getUniformLocation(program, 'atmos_ap_aspect'), aspect);
}

// HillaireModel::BuildFrame: for a camera inside the atmosphere, the sky-view
// table for its radius and sun, and the aerial-perspective volume for its frustum.
function buildHillaireFrame(gl, model, view, aspect) {
  var h = model.hillaire;
  var pos = view.camera.position;
  var r = Math.sqrt(vDot(pos, pos));
  if (!(r <= model.top)) return;
  var sun = vNormalize(view.sun);
  var mu_s = Math.max(-1, Math.min(1, vDot(sun, pos) / r));
  gl.disable(gl.SCISSOR_TEST);
  model.units.slice(0, model.bakedTextures.length).forEach(function (u) {
    var t = model.textures[u[1]];
    gl.activeTexture(gl.TEXTURE0 + u[1]);
    gl.bindTexture(t.target, t.texture);
  });
  gl.useProgram(h.sky);
  gl.uniform1f(gl.getUniformLocation(h.sky, 'u_r'), Math.max(r, model.bottom + 1.0));
  gl.uniform3fv(gl.getUniformLocation(h.sky, 'u_sun'),
                [Math.sqrt(Math.max(0, 1 - mu_s * mu_s)), 0, mu_s]);
  gl.bindFramebuffer(gl.FRAMEBUFFER, h.skyFb);
  gl.viewport(0, 0, 192, 108);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  gl.useProgram(h.ap);
  setApCamera(gl, h.ap, view.camera, aspect);
  gl.uniform3fv(gl.getUniformLocation(h.ap, 'u_camera'), pos);
  gl.uniform3fv(gl.getUniformLocation(h.ap, 'u_sun'), sun);
  gl.bindFramebuffer(gl.FRAMEBUFFER, h.apFb);
  gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1, gl.COLOR_ATTACHMENT2,
                  gl.COLOR_ATTACHMENT3]);
  gl.viewport(0, 0, 32, 32);
  for (var k = 0; k < 32; ++k) {
    var prev = h.apState[(k + 1) % 2], next = h.apState[k % 2];
    gl.framebufferTextureLayer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, h.apScatter.texture, 0, k);
    gl.framebufferTextureLayer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, h.apTransmittance.texture,
                               0, k);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT2, gl.TEXTURE_2D,
                            next[0].texture, 0);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT3, gl.TEXTURE_2D,
                            next[1].texture, 0);
    gl.activeTexture(gl.TEXTURE0 + h.prevUnit);
    gl.bindTexture(gl.TEXTURE_2D, prev[0].texture);
    gl.activeTexture(gl.TEXTURE0 + h.prevUnit + 1);
    gl.bindTexture(gl.TEXTURE_2D, prev[1].texture);
    gl.uniform1i(gl.getUniformLocation(h.ap, 'u_slice'), k);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }
}

function bindModel(gl, model) {
  gl.useProgram(model.program);
  model.textures.forEach(function (t, i) {
    gl.activeTexture(gl.TEXTURE0 + i);
    gl.bindTexture(t.target, t.texture);
  });
}

// Draws `view` with `model` into the bound framebuffer, pixels [x0, x1) of a
// width x height image.
function drawView(gl, model, view, width, height, opts, x0, x1, target) {
  if (model.hillaire) buildHillaireFrame(gl, model, view, width / height);
  gl.bindFramebuffer(gl.FRAMEBUFFER, target);
  bindModel(gl, model);
  var p = model.program;
  if (model.hillaire) setApCamera(gl, p, view.camera, width / height);
  function u(name) { return gl.getUniformLocation(p, name); }
  var c = view.camera;
  gl.uniform3fv(u('u_camera'), c.position);
  gl.uniform3fv(u('u_forward'), c.forward);
  gl.uniform3fv(u('u_right'), c.right);
  gl.uniform3fv(u('u_up'), c.up);
  gl.uniform1f(u('u_tan_half_fov_y'), c.tanHalfFovY);
  gl.uniform2f(u('u_size'), width, height);
  gl.uniform3fv(u('u_sun'), vNormalize(view.sun));
  gl.uniform1f(u('u_sun_irradiance'), view.irradiance === undefined ? 6.0 : view.irradiance);
  gl.uniform1f(u('u_exposure'), opts.exposure);
  gl.uniform1i(u('u_raw'), opts.raw ? 1 : 0);
  gl.uniform1i(u('u_sun_disc'), opts.sunDisc ? 1 : 0);
  gl.viewport(0, 0, width, height);
  gl.enable(gl.SCISSOR_TEST);
  gl.scissor(x0, 0, x1 - x0, height);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  gl.disable(gl.SCISSOR_TEST);
}

// ---- a bake's tables computed on the GPU (its JSON's "gpu_precompute") ----
// The schema is src/atmos/io/gpu_passes.h; any model whose bake lists passes
// runs here (the page asks the bake, never the model's name). Each pass: one
// full-screen triangle per layer of its target (uniform int atmos_layer),
// into float render targets (EXT_color_buffer_float), inputs sampled LINEAR
// and CLAMP_TO_EDGE; "add" passes blend ONE, ONE where float blending exists
// (EXT_float_blend for RGBA32F) and otherwise copy the layer, render into a
// scratch texture and add the two (?blend=copy forces that path).
var ADD_SHADER = [
  'uniform highp sampler2D u_old;',
  'uniform highp sampler2D u_new;',
  'out vec4 atmos_out;',
  'void main() {',
  '  ivec2 p = ivec2(gl_FragCoord.xy);',
  '  atmos_out = texelFetch(u_old, p, 0) + texelFetch(u_new, p, 0);',
  '}'].join('\n');

function hasPrecompute(model) { return !!model.data.bake.gpu_precompute; }

function makePrecompute(gl, model) {
  if (!gl.getExtension('EXT_color_buffer_float')) {
    throw new Error('the GPU precomputation needs EXT_color_buffer_float (float render targets)');
  }
  var spec = model.data.bake.gpu_precompute;
  var pc = {spec: spec, targets: {}, fb: gl.createFramebuffer(), scratch: {}};
  Object.keys(spec.targets).forEach(function (name) {
    var t = spec.targets[name];
    var tex = makeTarget(gl, t.depth > 1 ? gl.TEXTURE_3D : gl.TEXTURE_2D, t.width, t.height,
                         t.depth);
    pc.targets[name] = {width: t.width, height: t.height, depth: t.depth, tex: tex};
  });
  pc.internal = gl.getExtension('OES_texture_float_linear') ? gl.RGBA32F : gl.RGBA16F;
  pc.blend = atmosViewerParams.get('blend') !== 'copy' &&
             (pc.internal === gl.RGBA16F || !!gl.getExtension('EXT_float_blend'));
  if (!pc.blend) pc.addProgram = linkProgram(gl, GLSL_HEADER + ADD_SHADER);
  model.precompute = pc;
}

// The passes' programs over `constants` (the constants file of the bake's
// shader list replaced by them).
function linkPrecompute(gl, model, constants) {
  var pc = model.precompute, data = model.data;
  var body = pc.spec.shaders.map(function (path) {
    if (path === data.constantsPath) return constants;
    if (data.sources[path] === undefined) throw new Error('no shader ' + path + ' in model.js');
    return data.sources[path];
  }).join('\n');
  pc.programs = pc.spec.passes.map(function (pass) {
    // The schema's header: #version, the precision lines (int too), the entry.
    var program = linkProgram(gl, GLSL_HEADER + 'precision highp int;\n#define ' + pass.entry +
                                      ' 1\n' + body);
    gl.useProgram(program);
    Object.keys(pass.inputs).forEach(function (sampler, unit) {
      gl.uniform1i(gl.getUniformLocation(program, sampler), unit);
    });
    Object.keys(pass.uniforms).forEach(function (name) {
      gl.uniform1i(gl.getUniformLocation(program, name), pass.uniforms[name]);
    });
    return program;
  });
}

function attachLayer(gl, tex, z) {
  if (tex.target === gl.TEXTURE_3D) {
    gl.framebufferTextureLayer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, tex.texture, 0, z);
  } else {
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex.texture, 0);
  }
}
function scratchTexture(gl, pc, key, w, h) {
  var k = key + w + 'x' + h;
  if (!pc.scratch[k]) pc.scratch[k] = makeTarget(gl, gl.TEXTURE_2D, w, h, 1);
  return pc.scratch[k];
}

// Runs the passes (programs from linkPrecompute); the table targets then
// replace the baked textures of their units.
function runPrecompute(gl, model) {
  var pc = model.precompute;
  gl.disable(gl.SCISSOR_TEST);
  gl.disable(gl.BLEND);
  gl.bindFramebuffer(gl.FRAMEBUFFER, pc.fb);
  gl.drawBuffers([gl.COLOR_ATTACHMENT0]);
  pc.spec.passes.forEach(function (pass, i) {
    var program = pc.programs[i], out = pc.targets[pass.target];
    var bindInputs = function () {
      gl.useProgram(program);
      Object.keys(pass.inputs).forEach(function (sampler, unit) {
        var t = pc.targets[pass.inputs[sampler]].tex;
        gl.activeTexture(gl.TEXTURE0 + unit);
        gl.bindTexture(t.target, t.texture);
      });
    };
    bindInputs();
    var layer = gl.getUniformLocation(program, 'atmos_layer');
    gl.viewport(0, 0, out.width, out.height);
    for (var z = 0; z < out.depth; ++z) {
      if (layer) gl.uniform1i(layer, z);
      if (pass.blend !== 'add') {
        attachLayer(gl, out.tex, z);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
      } else if (pc.blend) {
        attachLayer(gl, out.tex, z);
        gl.enable(gl.BLEND);
        gl.blendEquation(gl.FUNC_ADD);
        gl.blendFunc(gl.ONE, gl.ONE);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
        gl.disable(gl.BLEND);
      } else {
        // Copy and add: old layer -> A, the pass -> B, then A + B -> the layer.
        var a = scratchTexture(gl, pc, 'old', out.width, out.height);
        var b = scratchTexture(gl, pc, 'new', out.width, out.height);
        attachLayer(gl, out.tex, z);
        gl.activeTexture(gl.TEXTURE0);
        gl.bindTexture(gl.TEXTURE_2D, a.texture);
        gl.copyTexSubImage2D(gl.TEXTURE_2D, 0, 0, 0, 0, 0, out.width, out.height);
        bindInputs();
        attachLayer(gl, b, 0);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
        attachLayer(gl, out.tex, z);
        gl.useProgram(pc.addProgram);
        gl.activeTexture(gl.TEXTURE0);
        gl.bindTexture(gl.TEXTURE_2D, a.texture);
        gl.activeTexture(gl.TEXTURE1);
        gl.bindTexture(gl.TEXTURE_2D, b.texture);
        gl.uniform1i(gl.getUniformLocation(pc.addProgram, 'u_old'), 0);
        gl.uniform1i(gl.getUniformLocation(pc.addProgram, 'u_new'), 1);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
        bindInputs();
      }
    }
  });
  Object.keys(pc.targets).forEach(function (name) {
    if (model.tableUnit[name] !== undefined) {
      model.textures[model.tableUnit[name]] = pc.targets[name].tex;
    }
  });
  pc.last = pc.targets[pc.spec.passes[pc.spec.passes.length - 1].target];
}

// Waits for the passes (timeDraw's sync): a one-texel read of the last target.
function syncPrecompute(gl, model) {
  var pc = model.precompute;
  gl.bindFramebuffer(gl.FRAMEBUFFER, pc.fb);
  attachLayer(gl, pc.last.tex, 0);
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.FLOAT, new Float32Array(4));
}

// Reads table target `name` back: its first `channels` per texel, layers in
// order (the layout of the raw blobs, src/atmos/io/raw_tables.h).
function readTarget(gl, model, name, channels) {
  var pc = model.precompute, t = pc.targets[name];
  var texels = t.width * t.height;
  var rgba = new Float32Array(texels * 4);
  var out = new Float32Array(texels * t.depth * channels);
  gl.bindFramebuffer(gl.FRAMEBUFFER, pc.fb);
  for (var z = 0; z < t.depth; ++z) {
    attachLayer(gl, t.tex, z);
    gl.readPixels(0, 0, t.width, t.height, gl.RGBA, gl.FLOAT, rgba);
    for (var i = 0; i < texels; ++i) {
      for (var c = 0; c < channels; ++c) out[(z * texels + i) * channels + c] = rgba[4 * i + c];
    }
  }
  return out;
}

// ---- the atmosphere: as baked, or a preset (presets.js), with scales ----
// The sliders scale the Rayleigh scattering (ray), the Mie scattering and
// extinction (mie) and the ozone absorption (oz); alb sets a grey ground
// albedo (-1: the atmosphere's own). The #defines of the atmosphere's
// constants are rewritten (9 digits, as the bake writes them) and the
// model's own #defines follow (model.js modelConstants).
var SCALED_DEFINES = {ATMOS_RAYLEIGH_SCATTERING: 'ray', ATMOS_MIE_SCATTERING: 'mie',
                      ATMOS_MIE_EXTINCTION: 'mie', ATMOS_ABSORPTION_EXTINCTION: 'oz'};
function isBakedAtmosphere(s) {
  return !s.atm && s.ray === 1 && s.mie === 1 && s.oz === 1 && s.alb < 0;
}
function fmtGlsl(x) { return x.toExponential(9); }
// {constants (the atmosphere's #defines), bottom, top, albedo} of the state's
// atmosphere for a model (its baked one unless s.atm names a preset).
function stateAtmosphere(s, model) {
  var preset = s.atm && window.atmosViewerPresets ? atmosViewerPresets[s.atm] : null;
  var text, bottom, top;
  if (preset) {
    text = preset.constants;
    bottom = preset.bottom;
    top = preset.top;
  } else {
    var c = model.data.constants;
    text = c.slice(0, c.length - model.data.modelConstants.length);
    bottom = model.data.bake.atmosphere.bottom_radius;
    top = model.data.bake.atmosphere.top_radius;
  }
  var lines = text.split('\n').map(function (line) {
    var m = /^#define (ATMOS_[A-Z_]+) vec3\(([^,]+), ([^,]+), ([^)]+)\)$/.exec(line);
    if (!m) return line;
    var v = [parseFloat(m[2]), parseFloat(m[3]), parseFloat(m[4])];
    if (SCALED_DEFINES[m[1]]) {
      var k = s[SCALED_DEFINES[m[1]]];
      if (k === 1) return line;
      v = v.map(function (x) { return x * k; });
    } else if (m[1] === 'ATMOS_GROUND_ALBEDO' && s.alb >= 0) {
      v = [s.alb, s.alb, s.alb];
    } else {
      return line;
    }
    return '#define ' + m[1] + ' vec3(' + v.map(fmtGlsl).join(', ') + ')';
  });
  return {constants: lines.join('\n'), bottom: bottom, top: top};
}
// Gives `model` the state's atmosphere: for a bake with GPU passes, the
// constants rewritten, the programs relinked and the tables computed on the
// GPU (timed: done(ms, label)); back to the baked tables and constants for
// the baked atmosphere. A bake without passes keeps its atmosphere (false).
function applyAtmosphere(gl, model, s, timer, done, forceGpu) {
  if (!hasPrecompute(model)) return false;
  var a = stateAtmosphere(s, model);
  var constants = a.constants + model.data.modelConstants;
  if (!forceGpu && isBakedAtmosphere(s)) {
    if (model.constants !== model.data.constants) linkModel(gl, model, model.data.constants);
    model.textures = model.textures.map(function (t, i) {
      return i < model.bakedTextures.length ? model.bakedTextures[i] : t;
    });
    model.bottom = a.bottom;
    model.top = a.top;
    model.gpuTables = false;
    if (done) done(NaN);
    return true;
  }
  if (!model.precompute) makePrecompute(gl, model);
  if (model.constants !== constants || !model.gpuTables) {
    linkModel(gl, model, constants);
    linkPrecompute(gl, model, constants);
  }
  model.bottom = a.bottom;
  model.top = a.top;
  model.gpuTables = true;
  timeDraw(gl, timer, function () { runPrecompute(gl, model); }, function (ms) {
    if (done) done(ms);
  }, function () { syncPrecompute(gl, model); });
  return true;
}

// ---- test mode: every view of every model into float images in the DOM ----
// ?test=1: the views from the baked tables (data-tables="baked"). With
// &tables=gpu, then every model whose bake has GPU passes computes its tables
// on the GPU for the atmosphere of the hash's state (the baked one by
// default), puts each table in the DOM (<pre class="atmos-table">: its raw
// layout as float32, base64) and renders the views again from them
// (data-tables="gpu").
function runTests(gl, format, blobs) {
  var out = document.getElementById('atmos-test');
  var size = (atmosViewerParams.get('size') || '320x180').split('x');
  var width = parseInt(size[0], 10), height = parseInt(size[1], 10);
  var gpu = atmosViewerParams.get('tables') === 'gpu';
  if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('no EXT_color_buffer_float');
  var fb = gl.createFramebuffer();
  var rb = gl.createRenderbuffer();
  gl.bindRenderbuffer(gl.RENDERBUFFER, rb);
  gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA32F, width, height);
  gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
  gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb);
  var pixels = new Float32Array(width * height * 4);
  var rgb = new Float32Array(width * height * 3);
  var html = [];
  var state = parseState(window.location.hash);
  var timer = makeTimer(gl, 'finish');
  function renderViews(name, model, tables) {
    var views = standardViews(model.bottom, model.top);
    // With a state in the hash, its view too (named "state"; a free camera
    // is `atmos render --camera --sun`'s, irradiance 1).
    if (window.location.hash) {
      var v = stateView(state, views, model.bottom);
      views.push({name: 'state', camera: v.camera, sun: v.sun, irradiance: v.irradiance});
    }
    views.forEach(function (view) {
      var t0 = performance.now();
      drawView(gl, model, view, width, height, {raw: true, sunDisc: false, exposure: 1}, 0,
               width, fb);
      gl.readPixels(0, 0, width, height, gl.RGBA, gl.FLOAT, pixels);
      var ms = performance.now() - t0;
      // Rows top-down, as the images of `atmos render`.
      for (var y = 0; y < height; ++y) {
        var src = (height - 1 - y) * width * 4, dst = y * width * 3;
        for (var x = 0; x < width; ++x) {
          rgb[dst + 3 * x] = pixels[src + 4 * x];
          rgb[dst + 3 * x + 1] = pixels[src + 4 * x + 1];
          rgb[dst + 3 * x + 2] = pixels[src + 4 * x + 2];
        }
      }
      html.push('<pre class="atmos-image" data-model="' + name + '" data-view="' + view.name +
                '" data-tables="' + tables + '" data-width="' + width + '" data-height="' +
                height + '" data-ms="' + ms.toFixed(1) + '">' + encodeBase64(rgb.buffer) +
                '</pre>');
    });
  }
  atmosViewerModels.forEach(function (name) {
    var model = makeModel(gl, name, format, blobs[name]);
    // The baked tables' views (and, with tables=gpu, the baked atmosphere's).
    renderViews(name, model, 'baked');
    if (!gpu || !hasPrecompute(model)) return;
    var ms = NaN;
    applyAtmosphere(gl, model, state, timer, function (t) { ms = t; }, true);
    var raw = model.data.bake.raw.tables;
    Object.keys(model.precompute.targets).forEach(function (t) {
      if (!raw[t]) return;  // a scratch target
      var e = raw[t];
      var values = readTarget(gl, model, t, e.channels);
      html.push('<pre class="atmos-table" data-model="' + name + '" data-table="' + t +
                '" data-width="' + e.width + '" data-height="' + e.height + '" data-depth="' +
                e.depth + '" data-channels="' + e.channels + '" data-ms="' + ms.toFixed(1) +
                '">' + encodeBase64(values.buffer) + '</pre>');
    });
    renderViews(name, model, 'gpu');
  });
  out.innerHTML = html.join('\n');
  out.setAttribute('data-status', 'ok');
}

// ---- the view's state, in the URL's hash (a link reproduces the view) ----
// Keys: m, m2 (left / right model), split (0|1), pos (the seam, 0..1 of the
// width), view (a standard view, or empty for the free camera below), alt
// (camera altitude, m), az, el (look azimuth clockwise from north, elevation,
// deg), fov (vertical, deg), sun_az, sun_el (deg), exp (log2 exposure), disc
// (sun disc 0|1). The free camera and sun are `atmos render --camera
// altitude=..,azimuth=..,elevation=..,fov=.. --sun elevation=..,azimuth=..`'s
// (src/atmos/harness/camera_spec.cpp), with its unit sun irradiance.
// The atmosphere (models whose bake has GPU passes recompute their tables
// for it): atm (an embedded preset, presets.js, or empty: as baked), ray, mie,
// oz (scales of the Rayleigh scattering, the Mie scattering and extinction,
// the ozone absorption; 0..10), alb (grey ground albedo 0..1, -1: the
// atmosphere's own).
var STATE_KEYS = ['m', 'm2', 'split', 'pos', 'view', 'alt', 'az', 'el', 'fov', 'sun_az', 'sun_el',
                  'exp', 'disc', 'atm', 'ray', 'mie', 'oz', 'alb'];
function defaultState() {
  var m = atmosViewerModels;
  return {m: m[0], m2: m.length > 1 ? m[1] : m[0], split: 0, pos: 0.5, view: '', alt: 0, az: 90,
          el: 10, fov: 60, sun_az: 90, sun_el: 6, exp: 2.6, disc: 1, atm: '', ray: 1, mie: 1,
          oz: 1, alb: -1};
}
function clampNum(x, lo, hi, fallback) {
  x = parseFloat(x);
  return isFinite(x) ? Math.min(hi, Math.max(lo, x)) : fallback;
}
// Rounds to `digits` decimals without a trailing '.0' ('1.5', '90', '-3.25').
function fmtNum(x, digits) { return String(parseFloat(x.toFixed(digits))); }
function parseState(text) {
  var p = new URLSearchParams(text.replace(/^[#?]/, ''));
  var s = defaultState();
  var known = function (n) { return atmosViewerModels.indexOf(n) >= 0; };
  if (p.has('m') && known(p.get('m'))) s.m = p.get('m');
  if (p.has('m2') && known(p.get('m2'))) s.m2 = p.get('m2');
  if (p.has('split')) s.split = p.get('split') === '1' ? 1 : 0;
  s.pos = clampNum(p.get('pos'), 0.05, 0.95, s.pos);
  if (p.has('view')) s.view = p.get('view');
  s.alt = clampNum(p.get('alt'), 0, 5e7, s.alt);
  s.az = clampNum(p.get('az'), -360, 360, s.az);
  s.el = clampNum(p.get('el'), -89.5, 89.5, s.el);
  s.fov = clampNum(p.get('fov'), 5, 120, s.fov);
  s.sun_az = clampNum(p.get('sun_az'), -360, 360, s.sun_az);
  s.sun_el = clampNum(p.get('sun_el'), -90, 90, s.sun_el);
  s.exp = clampNum(p.get('exp'), -4, 8, s.exp);
  if (p.has('disc')) s.disc = p.get('disc') === '0' ? 0 : 1;
  var presets = window.atmosViewerPresets || {};
  if (p.has('atm') && Object.prototype.hasOwnProperty.call(presets, p.get('atm'))) {
    s.atm = p.get('atm');
  }
  s.ray = clampNum(p.get('ray'), 0, 10, s.ray);
  s.mie = clampNum(p.get('mie'), 0, 10, s.mie);
  s.oz = clampNum(p.get('oz'), 0, 10, s.oz);
  s.alb = clampNum(p.get('alb'), -1, 1, s.alb);
  if (s.alb < 0) s.alb = -1;
  return s;
}
function formatState(s) {
  var v = {m: s.m, m2: s.m2, split: s.split ? 1 : 0, pos: fmtNum(s.pos, 3), view: s.view,
           alt: fmtNum(s.alt, 1), az: fmtNum(s.az, 2), el: fmtNum(s.el, 2), fov: fmtNum(s.fov, 2),
           sun_az: fmtNum(s.sun_az, 2), sun_el: fmtNum(s.sun_el, 2), exp: fmtNum(s.exp, 2),
           disc: s.disc ? 1 : 0, atm: s.atm, ray: fmtNum(s.ray, 3), mie: fmtNum(s.mie, 3),
           oz: fmtNum(s.oz, 3), alb: fmtNum(s.alb, 3)};
  return STATE_KEYS.map(function (k) {
    return k + '=' + encodeURIComponent(String(v[k]));
  }).join('&');
}
// A direction at azimuth (deg clockwise from north, +y; east +x) and elevation.
function compassDirection(azDeg, elDeg) {
  var a = radians(azDeg), e = radians(elDeg);
  return [Math.sin(a) * Math.cos(e), Math.cos(a) * Math.cos(e), Math.sin(e)];
}
// The view a state shows: a standard view (irradiance 6), or the free camera
// at (0, 0, R + alt) and free sun of `atmos render --camera/--sun` (irradiance 1).
function stateView(s, views, R) {
  for (var i = 0; i < views.length; ++i) {
    var v = views[i];
    // The picture of `atmos render --view` at irradiance 1 (its 6 is in the exposure).
    if (v.name === s.view) {
      return {name: v.name, irradiance: 1, camera: v.camera, sun: v.sun, exposure: v.exposure};
    }
  }
  return {name: '', irradiance: 1,
          camera: makeCamera([0, 0, R + s.alt], compassDirection(s.az, s.el), [0, 0, 1], s.fov),
          sun: compassDirection(s.sun_az, s.sun_el)};
}
// The free camera's sliders from a standard view's camera and sun (its exact
// position is kept only while the view stays selected), and its exposure
// unless `keepExposure`.
function stateFromView(s, v, R, keepExposure) {
  var pos = v.camera.position;
  s.alt = Math.max(Math.sqrt(vDot(pos, pos)) - R, 0);
  var f = v.camera.forward;
  s.az = Math.atan2(f[0], f[1]) * 180 / Math.PI;
  s.el = Math.min(89.5, Math.max(-89.5, Math.asin(Math.max(-1, Math.min(1, f[2]))) * 180 /
                                            Math.PI));
  s.fov = v.camera.vfov;
  var sun = vNormalize(v.sun);
  s.sun_az = Math.atan2(sun[0], sun[1]) * 180 / Math.PI;
  s.sun_el = Math.asin(sun[2]) * 180 / Math.PI;
  // The same picture at the free view's irradiance 1: exposure x 6.
  if (!keepExposure) s.exp = Math.log2(v.exposure * 6);
}
// The flags of `atmos render` for the state's atmosphere: --atmosphere PRESET
// and a --set per changed field, with the values the page's constants hold.
var SET_FIELDS = {ATMOS_RAYLEIGH_SCATTERING: 'rayleigh_scattering',
                  ATMOS_MIE_SCATTERING: 'mie_scattering', ATMOS_MIE_EXTINCTION: 'mie_extinction',
                  ATMOS_ABSORPTION_EXTINCTION: 'absorption_extinction'};
function atmosphereFlags(s, model) {
  if (!model || !hasPrecompute(model) || isBakedAtmosphere(s)) return '';
  var flags = s.atm ? ' --atmosphere ' + s.atm : '';
  stateAtmosphere(s, model).constants.split('\n').forEach(function (line) {
    var m = /^#define (ATMOS_[A-Z_]+) vec3\(([^,]+), ([^,]+), ([^)]+)\)$/.exec(line);
    if (!m || !SET_FIELDS[m[1]] || s[SCALED_DEFINES[m[1]]] === 1) return;
    flags += ' --set ' + SET_FIELDS[m[1]] + '=' + [m[2], m[3], m[4]].map(function (x) {
      return String(parseFloat(x));
    }).join(',');
  });
  if (s.alb >= 0) flags += ' --set ground_albedo=' + fmtNum(s.alb, 3);
  return flags;
}
// `atmos render` of the left model's view (the page's pixels, PNG output).
function renderCommand(s, W, H, model) {
  var cmd = 'atmos render --model ' + s.m + atmosphereFlags(s, model) + ' ';
  if (s.view) {
    cmd += '--view ' + s.view;
  } else {
    cmd += '--camera altitude=' + fmtNum(s.alt, 1) + ',azimuth=' + fmtNum(s.az, 2) +
           ',elevation=' + fmtNum(s.el, 2) + ',fov=' + fmtNum(s.fov, 2) + ' --sun elevation=' +
           fmtNum(s.sun_el, 2) + ',azimuth=' + fmtNum(s.sun_az, 2);
  }
  var exposure = Math.pow(2, s.exp) * (s.view ? 1 / 6 : 1);
  return cmd + (s.disc ? ' --sun-disc' : '') + ' --exposure ' + fmtNum(exposure, 4) +
         ' --size ' + W + 'x' + H + ' -o view.png';
}

// ---- GPU timing: EXT_disjoint_timer_query_webgl2 where the browser has it ----
function makeTimer(gl, force) {
  var ext = force === 'finish' ? null : gl.getExtension('EXT_disjoint_timer_query_webgl2');
  return {ext: ext, label: ext ? 'gpu-timer' : 'finish', pixel: new Uint8Array(4)};
}
// Times draw() on the GPU (timer query; done(ms) once the result is in, polled
// from later tasks) or, without the extension, by performance.now() around
// draw(), gl.finish() and a one-pixel readPixels (the CPU waits for the GPU;
// includes the browser's and driver's overhead), done(ms) at once.
// `sync` (optional): the one-pixel read for draws into float targets.
function timeDraw(gl, timer, draw, done, sync) {
  var read = sync || function () {
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, timer.pixel);
  };
  if (!timer.ext) {
    var t0 = performance.now();
    draw();
    gl.finish();
    // finish() need not wait in a browser (Chromium's returns at once): a
    // one-pixel read of the drawn framebuffer does.
    read();
    done(performance.now() - t0);
    return;
  }
  var q = gl.createQuery();
  gl.beginQuery(timer.ext.TIME_ELAPSED_EXT, q);
  draw();
  gl.endQuery(timer.ext.TIME_ELAPSED_EXT);
  // Wait for the draw (the query times the GPU only): the result is then
  // ready at the next task (WebGL makes it available no sooner).
  read();
  var poll = function () {
    if (!gl.getQueryParameter(q, gl.QUERY_RESULT_AVAILABLE)) { setTimeout(poll, 1); return; }
    var disjoint = gl.getParameter(timer.ext.GPU_DISJOINT_EXT);
    var ns = gl.getQueryParameter(q, gl.QUERY_RESULT);
    gl.deleteQuery(q);
    done(disjoint ? NaN : ns / 1e6);
  };
  setTimeout(poll, 0);
}
function median(xs) {
  var v = xs.filter(function (x) { return isFinite(x); }).sort(function (a, b) { return a - b; });
  if (v.length === 0) return NaN;
  var h = v.length >> 1;
  return v.length % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

// ---- benchmark mode (?bench=N[&size=WxH][&timer=finish]) ----
// (The frames come first, then each GPU precomputation; see nextPrecompute.)
// Per model, one frame of the state's view at WxH (default 1920x1080) into an
// RGBA8 framebuffer as the page shows it (hillaire's sky-view and
// aerial-perspective passes included), once to warm up (shader compiles) and
// then N times; prints the median, also to the console, one line a model:
//   atmos-bench model=NAME size=WxH runs=N median_ms=X min_ms=Y timer=gpu-timer|finish
function runBench(gl, models, state, views, done) {
  var runs = Math.max(1, Math.min(1000, parseInt(atmosViewerParams.get('bench'), 10) || 1));
  var size = (atmosViewerParams.get('size') || '1920x1080').split('x');
  var width = parseInt(size[0], 10), height = parseInt(size[1], 10);
  var timer = makeTimer(gl, atmosViewerParams.get('timer'));
  var fb = gl.createFramebuffer();
  var rb = gl.createRenderbuffer();
  gl.bindRenderbuffer(gl.RENDERBUFFER, rb);
  gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA8, width, height);
  gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
  gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb);
  var out = document.getElementById('atmos-bench');
  var renderer = gl.getParameter(gl.RENDERER);
  var info = gl.getExtension('WEBGL_debug_renderer_info');
  if (info) renderer = gl.getParameter(info.UNMASKED_RENDERER_WEBGL);
  var lines = ['atmos-bench renderer="' + String(renderer).replace(/"/g, "'") + '" timer=' +
               timer.label + (timer.ext ? '' : ' (performance.now around draw, gl.finish and a ' +
                                             'one-pixel readPixels: includes browser overhead)')];
  out.textContent = lines.join('\n');
  console.log(lines[0]);
  var names = atmosViewerModels.slice();
  var opts = {raw: false, sunDisc: !!state.disc, exposure: Math.pow(2, state.exp)};
  // Then each model whose bake lists GPU passes: its precomputation for the
  // state's atmosphere, once to warm up (it links the programs) and N times:
  //   atmos-bench-precompute model=NAME runs=N median_ms=X min_ms=Y timer=...
  var precompute = atmosViewerModels.filter(function (n) { return hasPrecompute(models[n]); });
  function nextPrecompute() {
    if (precompute.length === 0) {
      out.setAttribute('data-status', 'done');
      if (done) done();
      return;
    }
    var name = precompute.shift(), model = models[name];
    var times = [], left = runs;
    var draw = function () { runPrecompute(gl, model); };
    var sync = function () { syncPrecompute(gl, model); };
    applyAtmosphere(gl, model, state, timer, function () {
      var again = function () {
        timeDraw(gl, timer, draw, function (ms) {
          times.push(ms);
          if (--left > 0) { again(); return; }
          var line = 'atmos-bench-precompute model=' + name + ' runs=' + runs + ' median_ms=' +
                     median(times).toFixed(3) + ' min_ms=' +
                     Math.min.apply(null, times).toFixed(3) + ' timer=' + timer.label;
          lines.push(line);
          console.log(line);
          out.textContent = lines.join('\n');
          nextPrecompute();
        }, sync);
      };
      again();
    }, true);
  }
  function nextModel() {
    if (names.length === 0) {
      nextPrecompute();
      return;
    }
    var name = names.shift(), model = models[name];
    var view = stateView(state, views, model.bottom);
    var draw = function () { drawView(gl, model, view, width, height, opts, 0, width, fb); };
    var times = [];
    timeDraw(gl, timer, draw, function () {  // the warm-up frame
      var left = runs;
      var again = function () {
        timeDraw(gl, timer, draw, function (ms) {
          times.push(ms);
          if (--left > 0) { again(); return; }
          var line = 'atmos-bench model=' + name + ' size=' + width + 'x' + height + ' runs=' +
                     runs + ' median_ms=' + median(times).toFixed(3) + ' min_ms=' +
                     Math.min.apply(null, times).toFixed(3) + ' timer=' + timer.label;
          lines.push(line);
          console.log(line);
          out.textContent = lines.join('\n');
          nextModel();
        });
      };
      again();
    });
  }
  nextModel();
}

// ---- interactive viewer ----
function atmosViewerMain() {
  var status = document.getElementById('atmos-test');
  var errorBox = document.getElementById('error');
  var format = atmosViewerParams.get('format');
  var canvas = document.getElementById('canvas');
  var gl = canvas.getContext('webgl2', {antialias: false, preserveDrawingBuffer: true});
  function report(e) {
    status.setAttribute('data-status', 'error');
    status.setAttribute('data-error', String(e.message || e));
    errorBox.textContent = String(e.message || e);
  }
  try {
    if (!gl) throw new Error('WebGL2 is not available in this browser');
    var linear = gl.getExtension('OES_texture_float_linear');
    if (format === 'f32' && !linear) {
      throw new Error('float32 tables need OES_texture_float_linear; open with ?format=f16');
    }
    var sync = !!(atmosViewerParams.get('test') || atmosViewerParams.get('bench'));
    loadTables(atmosViewerModels, sync, function (blobs) {
      try {
        if (atmosViewerParams.get('test') === '1') {
          runTests(gl, format, blobs);
          return;
        }
        runViewer(gl, canvas, format, blobs);
      } catch (e) {
        report(e);
      }
    }, report);
  } catch (e) {
    report(e);
  }
}

function runViewer(gl, canvas, format, blobs) {
  var models = {};
  atmosViewerModels.forEach(function (name) {
    models[name] = makeModel(gl, name, format, blobs[name]);
  });
  var first = models[atmosViewerModels[0]];
  var R = first.bottom;
  var views = standardViews(first.bottom, first.top);
  var timer = makeTimer(gl, atmosViewerParams.get('timer'));
  var el = function (id) { return document.getElementById(id); };
  var viewSelect = el('view');
  var custom = document.createElement('option');
  custom.textContent = '(free camera)';
  custom.value = '';
  viewSelect.appendChild(custom);
  views.forEach(function (v) {
    var o = document.createElement('option');
    o.textContent = v.name;
    o.value = v.name;
    viewSelect.appendChild(o);
  });
  ['model', 'model2'].forEach(function (id) {
    atmosViewerModels.forEach(function (name) {
      var o = document.createElement('option');
      o.textContent = name;
      o.value = name;
      el(id).appendChild(o);
    });
  });
  // Hash first; the older query parameters view=NAME and split=1 still work.
  var state = parseState(window.location.hash);
  if (!window.location.hash) {
    if (atmosViewerParams.get('view')) state.view = atmosViewerParams.get('view');
    if (atmosViewerParams.get('split')) state.split = 1;
  }
  var known = views.some(function (v) { return v.name === state.view; });
  if (!known) state.view = '';
  var hashHasExposure = new URLSearchParams(window.location.hash.slice(1)).has('exp');
  if (state.view) stateFromView(state, stateView(state, views, R), R, hashHasExposure);

  // Altitude slider 0..1000 -> 0 m .. 50 000 km, exponential.
  function altFromSlider(v) { var s = v / 1000; return s === 0 ? 0 : Math.pow(10, 1 + s * 6.7) - 10; }
  function sliderFromAlt(a) {
    return a <= 0 ? 0 : Math.round((Math.log10(a + 10) - 1) / 6.7 * 1000);
  }
  function fmtAlt(a) { return a < 1e4 ? a.toFixed(0) + ' m' : (a / 1e3).toFixed(0) + ' km'; }
  var sliders = {sun_el: 'sun_el', sun_az: 'sun_az', az: 'yaw', el: 'pitch', fov: 'fov',
                 exp: 'exposure', pos: 'split_pos'};
  function showState() {
    viewSelect.value = state.view;
    el('model').value = state.m;
    el('model2').value = state.m2;
    el('split').checked = !!state.split;
    el('sun_disc').checked = !!state.disc;
    Object.keys(sliders).forEach(function (k) { el(sliders[k]).value = state[k]; });
    el('alt').value = sliderFromAlt(state.alt);
    el('sun_el_v').textContent = fmtNum(state.sun_el, 1) + '\u00b0';
    el('sun_az_v').textContent = fmtNum(state.sun_az, 1) + '\u00b0';
    el('alt_v').textContent = fmtAlt(state.alt);
    el('yaw_v').textContent = fmtNum(state.az, 1) + '\u00b0';
    el('pitch_v').textContent = fmtNum(state.el, 1) + '\u00b0';
    el('fov_v').textContent = fmtNum(state.fov, 1) + '\u00b0';
    el('exposure_v').textContent = 'x' + Math.pow(2, state.exp).toFixed(2);
    el('split_pos_v').textContent = fmtNum(state.pos, 2);
    // The seam and the labels of the split view.
    el('seam').hidden = !state.split;
    el('label2').hidden = !state.split;
    el('seam').style.left = (state.pos * 100) + '%';
    el('label1').textContent = state.m;
    el('label2').textContent = state.m2;
    el('label2').style.left = 'calc(' + (state.pos * 100) + '% + 8px)';
  }
  function publish() {
    var text = formatState(state);
    // The whole state in the URL (replaceState: no history entry per slider step).
    if (window.location.hash !== '#' + text) {
      window.history.replaceState(null, '', window.location.pathname + window.location.search +
                                                '#' + text);
    }
    el('atmos-test').setAttribute('data-state', text);
    el('atmos-test').setAttribute('data-hash', window.location.hash);
  }
  viewSelect.addEventListener('change', function () {
    state.view = viewSelect.value;
    if (state.view) stateFromView(state, stateView(state, views, R), R);
    changed();
  });
  Object.keys(sliders).forEach(function (k) {
    el(sliders[k]).addEventListener('input', function () {
      state[k] = +el(sliders[k]).value;
      if (k !== 'exp' && k !== 'pos') state.view = '';  // the camera or sun moved
      changed();
    });
  });
  el('alt').addEventListener('input', function () {
    state.alt = altFromSlider(+el('alt').value);
    state.view = '';
    changed();
  });
  el('model').addEventListener('change', function () { state.m = el('model').value; changed(); });
  el('model2').addEventListener('change', function () { state.m2 = el('model2').value; changed(); });
  el('split').addEventListener('change', function () { state.split = el('split').checked ? 1 : 0; changed(); });
  el('sun_disc').addEventListener('change', function () { state.disc = el('sun_disc').checked ? 1 : 0; changed(); });
  window.addEventListener('hashchange', function () {
    if (window.location.hash === '#' + formatState(state)) return;
    state = parseState(window.location.hash);
    if (!views.some(function (v) { return v.name === state.view; })) state.view = '';
    var keep = new URLSearchParams(window.location.hash.slice(1)).has('exp');
    if (state.view) stateFromView(state, stateView(state, views, R), R, keep);
    changed();
  });
  // Mouse look: dragging turns the camera (the scene follows the pointer);
  // the sun stays where it is.
  var drag = null;
  canvas.addEventListener('pointerdown', function (e) {
    drag = {x: e.clientX, y: e.clientY};
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointerup', function () { drag = null; });
  canvas.addEventListener('pointermove', function (e) {
    if (!drag) return;
    var degPerPixel = state.fov / Math.max(1, canvas.clientHeight);
    state.az = ((state.az - (e.clientX - drag.x) * degPerPixel + 540) % 360) - 180;
    state.el = Math.min(89.5, Math.max(-89.5, state.el + (e.clientY - drag.y) * degPerPixel));
    drag = {x: e.clientX, y: e.clientY};
    state.view = '';
    changed();
  });
  var pending = false, lastMs = NaN;
  // The atmosphere's sliders and preset menu (state keys atm, ray, mie, oz,
  // alb): each model whose bake lists GPU passes recomputes its tables on the
  // GPU when they change; the timings show in #precompute.
  var atmSliders = {ray: 'ray', mie: 'mie', oz: 'oz'};
  var presetSelect = el('atm');
  var asBaked = document.createElement('option');
  asBaked.textContent = '(as baked)';
  asBaked.value = '';
  presetSelect.appendChild(asBaked);
  Object.keys(window.atmosViewerPresets || {}).forEach(function (name) {
    var o = document.createElement('option');
    o.textContent = name;
    o.value = name;
    presetSelect.appendChild(o);
  });
  var atmosphereKey = '', precomputeMs = {};
  function showAtmosphere() {
    presetSelect.value = state.atm;
    Object.keys(atmSliders).forEach(function (k) {
      el(atmSliders[k]).value = state[k];
      el(atmSliders[k] + '_v').textContent = 'x' + fmtNum(state[k], 2);
    });
    el('alb').value = Math.max(0, state.alb);
    el('alb_v').textContent = state.alb < 0 ? 'own' : fmtNum(state.alb, 2);
  }
  function updateAtmosphere() {
    var key = [state.atm, state.ray, state.mie, state.oz, state.alb].join(',');
    if (key === atmosphereKey) return;
    atmosphereKey = key;
    var fixed = [];
    atmosViewerModels.forEach(function (name) {
      try {
        var ok = applyAtmosphere(gl, models[name], state, timer, function (ms) {
          precomputeMs[name] = ms;
          showPrecompute();
        });
        if (!ok) fixed.push(name);
      } catch (e) {
        // No float render targets, or a pass that does not compile: the
        // model keeps what it had, and the page says why.
        el('error').textContent = name + ': ' + String(e.message || e);
        fixed.push(name);
      }
    });
    // The views follow the planet (the first model's).
    R = models[atmosViewerModels[0]].bottom;
    views = standardViews(R, models[atmosViewerModels[0]].top);
    el('atm_note').textContent = fixed.length ?
        'baked atmosphere kept (no GPU passes in its bake, or the error below): ' +
        fixed.join(', ') : '';
  }
  function showPrecompute() {
    var parts = [];
    Object.keys(precomputeMs).forEach(function (name) {
      var ms = precomputeMs[name];
      if (isFinite(ms)) parts.push(name + ' ' + ms.toFixed(2) + ' ms');
    });
    el('precompute').textContent = parts.length ?
        'tables on the GPU: ' + parts.join(', ') + ' (' +
            (timer.ext ? 'GPU timer query' : 'finish-bracketed, not a GPU timer') + ')' :
        'tables: as baked (CPU)';
  }
  presetSelect.addEventListener('change', function () {
    state.atm = presetSelect.value;
    state.view = '';
    changed();
  });
  Object.keys(atmSliders).forEach(function (k) {
    el(atmSliders[k]).addEventListener('input', function () {
      state[k] = +el(atmSliders[k]).value;
      changed();
    });
  });
  el('alb').addEventListener('input', function () { state.alb = +el('alb').value; changed(); });
  function changed() {
    showState();
    showAtmosphere();
    publish();
    if (!pending) {
      pending = true;
      window.requestAnimationFrame(function () { pending = false; draw(); });
    }
  }
  // Draws on demand (a state change), not in a loop.
  function draw() {
    var w = canvas.clientWidth || 960;
    var h = Math.round(w * 9 / 16);
    var dpr = window.devicePixelRatio || 1;
    if (canvas.width !== Math.round(w * dpr)) {
      canvas.width = Math.round(w * dpr);
      canvas.height = Math.round(h * dpr);
    }
    var W = canvas.width, H = canvas.height;
    updateAtmosphere();
    var view = stateView(state, views, R);
    var opts = {raw: false, sunDisc: !!state.disc, exposure: Math.pow(2, state.exp)};
    var a = models[state.m], b = models[state.m2];
    var xs = Math.round(state.pos * W);
    timeDraw(gl, timer, function () {
      if (state.split) {
        drawView(gl, a, view, W, H, opts, 0, xs, null);
        drawView(gl, b, view, W, H, opts, xs, W, null);
      } else {
        drawView(gl, a, view, W, H, opts, 0, W, null);
      }
    }, function (ms) {
      lastMs = ms;
      el('stats').textContent = 'draw ' + (isFinite(lastMs) ? lastMs.toFixed(2) + ' ms' : '?') +
                                ' (' + (timer.ext ? 'GPU timer query' : 'finish/readPixels-bracketed, ' +
                                        'not a GPU timer') + '), ' + W + 'x' + H + ', tables ' +
                                format;
    });
    el('command').textContent = renderCommand(state, W, H, models[state.m]);
  }
  showState();
  showAtmosphere();
  publish();
  showPrecompute();
  draw();
  el('atmos-test').setAttribute('data-status', 'viewer');
  if (atmosViewerParams.get('bench')) runBench(gl, models, state, views);
}

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
function decodeBase64(text) {
  var bin = atob(text);
  var bytes = new Uint8Array(bin.length);
  for (var i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
  return bytes.buffer;
}
function encodeBase64(buffer) {
  var bytes = new Uint8Array(buffer);
  var parts = [];
  for (var i = 0; i < bytes.length; i += 0x8000) {
    parts.push(String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000)));
  }
  return btoa(parts.join(''));
}

// A texture from the bake's raw blob: "raw" -> tables -> NAME gives sizes and
// offsets (src/atmos/io/raw_tables.h).
function makeTexture(gl, blob, format, entry) {
  var half = format === 'f16';
  var n = entry.values;
  var data = half ? new Uint16Array(blob, entry.float16_offset, n)
                  : new Float32Array(blob, entry.float32_offset, n);
  var c = entry.channels;
  var internal = c === 4 ? (half ? gl.RGBA16F : gl.RGBA32F) : (half ? gl.RGB16F : gl.RGB32F);
  var fmt = c === 4 ? gl.RGBA : gl.RGB;
  var type = half ? gl.HALF_FLOAT : gl.FLOAT;
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

// One model: its program (GLSL ES header + the bake's constants + common.glsl
// and the model's functions + MAIN_SHADER) and its textures.
function makeModel(gl, name, format) {
  var data = atmosViewerData.models[name];
  var blobText = atmosViewerData.tables[name + '/' + format];
  // A model without tables (hosek-wilkie: constants only) has an empty blob.
  if (!data || blobText === undefined) throw new Error('no baked data for model ' + name);
  var fragment = '#version 300 es\nprecision highp float;\nprecision highp sampler2D;\n' +
                 'precision highp sampler3D;\n' + data.constants + '\n' + data.functions +
                 '\n' + MAIN_SHADER;
  var program = linkProgram(gl, fragment);
  var blob = decodeBase64(blobText);
  var raw = data.bake.raw.tables;
  // Texture units: the sampler names of the model's GLSL file.
  var samplers = {
    bruneton: [['atmos_transmittance_texture', 'transmittance'],
               ['atmos_irradiance_texture', 'irradiance'],
               ['atmos_scattering_texture', 'scattering'],
               ['atmos_single_mie_texture', 'single_mie_scattering']],
    hillaire: [['atmos_transmittance_texture', 'transmittance'],
               ['atmos_multiple_scattering_texture', 'multiple_scattering']],
    'atmosphere-plus': [['atmos_scattering_texture', 'scattering'],
                        ['atmos_transmittance_texture', 'transmittance']],
    'hosek-wilkie': []}[name];
  var textures = [];
  gl.useProgram(program);
  samplers.forEach(function (s) {
    if (!raw[s[1]]) return;
    var t = makeTexture(gl, blob, format, raw[s[1]]);
    gl.uniform1i(gl.getUniformLocation(program, s[0]), textures.length);
    textures.push(t);
  });
  var atm = data.bake.atmosphere;
  var model = {name: name, program: program, textures: textures,
               bottom: atm.bottom_radius, top: atm.top_radius};
  if (name === 'hillaire') makeHillaireFrame(gl, model, fragment.replace(MAIN_SHADER, ''));
  return model;
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

function makeHillaireFrame(gl, model, base) {
  if (!gl.getExtension('EXT_color_buffer_float')) {
    throw new Error('hillaire needs EXT_color_buffer_float (float render targets)');
  }
  var sky = makeTarget(gl, gl.TEXTURE_2D, 192, 108, 1);
  var apS = makeTarget(gl, gl.TEXTURE_3D, 32, 32, 32);
  var apT = makeTarget(gl, gl.TEXTURE_3D, 32, 32, 32);
  var units = [['atmos_sky_view_texture', sky], ['atmos_ap_scatter_texture', apS],
               ['atmos_ap_transmittance_texture', apT]];
  gl.useProgram(model.program);
  units.forEach(function (u) {
    gl.uniform1i(gl.getUniformLocation(model.program, u[0]), model.textures.length);
    model.textures.push(u[1]);
  });
  // Ping-pong copies of one slice's L and T for the next slice.
  var state = [0, 1].map(function () {
    return [makeTarget(gl, gl.TEXTURE_2D, 32, 32, 1), makeTarget(gl, gl.TEXTURE_2D, 32, 32, 1)];
  });
  var passes = {sky: linkProgram(gl, base + SKY_VIEW_MAIN), ap: linkProgram(gl, base + AP_MAIN),
                skyTarget: sky, apScatter: apS, apTransmittance: apT, apState: state,
                skyFb: gl.createFramebuffer(), apFb: gl.createFramebuffer()};
  [passes.sky, passes.ap].forEach(function (p) {
    gl.useProgram(p);
    gl.uniform1i(gl.getUniformLocation(p, 'atmos_transmittance_texture'), 0);
    gl.uniform1i(gl.getUniformLocation(p, 'atmos_multiple_scattering_texture'), 1);
  });
  gl.uniform1i(gl.getUniformLocation(passes.ap, 'u_prev_scatter'), 2);
  gl.uniform1i(gl.getUniformLocation(passes.ap, 'u_prev_transmittance'), 3);
  gl.bindFramebuffer(gl.FRAMEBUFFER, passes.skyFb);
  gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, sky.texture, 0);
  model.hillaire = passes;
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
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, model.textures[0].texture);
  gl.activeTexture(gl.TEXTURE1);
  gl.bindTexture(gl.TEXTURE_2D, model.textures[1].texture);
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
    gl.activeTexture(gl.TEXTURE2);
    gl.bindTexture(gl.TEXTURE_2D, prev[0].texture);
    gl.activeTexture(gl.TEXTURE3);
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
  gl.uniform1f(u('u_sun_irradiance'), 6.0);
  gl.uniform1f(u('u_exposure'), opts.exposure);
  gl.uniform1i(u('u_raw'), opts.raw ? 1 : 0);
  gl.uniform1i(u('u_sun_disc'), opts.sunDisc ? 1 : 0);
  gl.viewport(0, 0, width, height);
  gl.enable(gl.SCISSOR_TEST);
  gl.scissor(x0, 0, x1 - x0, height);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  gl.disable(gl.SCISSOR_TEST);
}

// ---- test mode: every view of every model into float images in the DOM ----
function runTests(gl, format) {
  var out = document.getElementById('atmos-test');
  var size = (atmosViewerParams.get('size') || '320x180').split('x');
  var width = parseInt(size[0], 10), height = parseInt(size[1], 10);
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
  atmosViewerModels.forEach(function (name) {
    var model = makeModel(gl, name, format);
    standardViews(model.bottom, model.top).forEach(function (view) {
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
                '" data-width="' + width + '" data-height="' + height + '" data-ms="' +
                ms.toFixed(1) + '">' + encodeBase64(rgb.buffer) + '</pre>');
    });
  });
  out.innerHTML = html.join('\n');
  out.setAttribute('data-status', 'ok');
}

// ---- interactive viewer ----
function atmosViewerMain() {
  var status = document.getElementById('atmos-test');
  var errorBox = document.getElementById('error');
  var format = atmosViewerParams.get('format');
  var canvas = document.getElementById('canvas');
  var gl = canvas.getContext('webgl2', {antialias: false, preserveDrawingBuffer: true});
  try {
    if (!gl) throw new Error('WebGL2 is not available in this browser');
    var linear = gl.getExtension('OES_texture_float_linear');
    if (format === 'f32' && !linear) {
      throw new Error('float32 tables need OES_texture_float_linear; open with ?format=f16');
    }
    if (atmosViewerParams.get('test')) {
      runTests(gl, format);
      return;
    }
    runViewer(gl, canvas, format);
  } catch (e) {
    status.setAttribute('data-status', 'error');
    status.setAttribute('data-error', String(e.message || e));
    errorBox.textContent = String(e.message || e);
  }
}

function runViewer(gl, canvas, format) {
  var models = {};
  atmosViewerModels.forEach(function (name) { models[name] = makeModel(gl, name, format); });
  var first = models[atmosViewerModels[0]];
  var views = standardViews(first.bottom, first.top);
  var el = function (id) { return document.getElementById(id); };
  var viewSelect = el('view');
  var custom = document.createElement('option');
  custom.textContent = '(sliders)';
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
  var preset = null;  // a standard view's exact camera until a slider moves
  // Altitude slider 0..1000 -> 0 m .. 50 000 km, quadratic-exponential.
  function altitude() {
    var s = el('alt').value / 1000;
    return s === 0 ? 0 : Math.pow(10, 1 + s * 6.7) - 10;
  }
  function fmtAlt(a) { return a < 1e4 ? a.toFixed(0) + ' m' : (a / 1e3).toFixed(0) + ' km'; }
  function sliderView() {
    var R = first.bottom;
    var sun = azimuthElevation(+el('sun_az').value, +el('sun_el').value);
    var camera = makeCamera([0, 0, R + altitude()],
                            azimuthElevation(+el('yaw').value, +el('pitch').value), [0, 0, 1],
                            +el('fov').value);
    return {name: '', camera: camera, sun: sun};
  }
  function setSlidersFrom(v) {
    var pos = v.camera.position;
    var r = Math.sqrt(vDot(pos, pos));
    var a = Math.max(r - first.bottom, 0);
    el('alt').value = a <= 0 ? 0 : Math.round((Math.log10(a + 10) - 1) / 6.7 * 1000);
    var f = v.camera.forward;
    el('yaw').value = Math.atan2(f[1], f[0]) * 180 / Math.PI;
    el('pitch').value = Math.asin(Math.max(-1, Math.min(1, f[2]))) * 180 / Math.PI;
    el('fov').value = v.camera.vfov;
    el('sun_el').value = Math.asin(v.sun[2]) * 180 / Math.PI;
    el('sun_az').value = Math.atan2(v.sun[1], v.sun[0]) * 180 / Math.PI;
    el('exposure').value = Math.log2(v.exposure);
  }
  viewSelect.addEventListener('change', function () {
    preset = null;
    views.forEach(function (v) { if (v.name === viewSelect.value) preset = v; });
    if (preset) setSlidersFrom(preset);
  });
  ['sun_el', 'sun_az', 'alt', 'yaw', 'pitch', 'fov'].forEach(function (id) {
    el(id).addEventListener('input', function () { preset = null; viewSelect.value = ''; });
  });
  var frameTimes = [];
  var last = performance.now();
  function frame() {
    var w = canvas.clientWidth || 960;
    var h = Math.round(w * 9 / 16);
    var dpr = window.devicePixelRatio || 1;
    if (canvas.width !== Math.round(w * dpr)) {
      canvas.width = Math.round(w * dpr);
      canvas.height = Math.round(h * dpr);
    }
    var view = preset || sliderView();
    var opts = {raw: false, sunDisc: el('sun_disc').checked,
                exposure: Math.pow(2, +el('exposure').value)};
    var W = canvas.width, H = canvas.height;
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    var t0 = performance.now();
    var a = models[el('model').value], b = models[el('model2').value];
    if (el('split').checked) {
      drawView(gl, a, view, W, H, opts, 0, W >> 1, null);
      drawView(gl, b, view, W, H, opts, W >> 1, W, null);
    } else {
      drawView(gl, a, view, W, H, opts, 0, W, null);
    }
    gl.finish();
    var draw = performance.now() - t0;
    var now = performance.now();
    frameTimes.push(now - last);
    last = now;
    if (frameTimes.length > 30) frameTimes.shift();
    var avg = frameTimes.reduce(function (s, x) { return s + x; }, 0) / frameTimes.length;
    el('stats').textContent = 'frame ' + avg.toFixed(1) + ' ms, draw ' + draw.toFixed(1) +
                              ' ms, ' + W + 'x' + H + ', tables ' + format;
    el('sun_el_v').textContent = (+el('sun_el').value).toFixed(1) + '\u00b0';
    el('sun_az_v').textContent = (+el('sun_az').value).toFixed(1) + '\u00b0';
    el('alt_v').textContent = fmtAlt(preset ? Math.sqrt(vDot(view.camera.position,
                                                             view.camera.position)) -
                                                  first.bottom : altitude());
    el('yaw_v').textContent = (+el('yaw').value).toFixed(1) + '\u00b0';
    el('pitch_v').textContent = (+el('pitch').value).toFixed(1) + '\u00b0';
    el('fov_v').textContent = (+el('fov').value).toFixed(1) + '\u00b0';
    el('exposure_v').textContent = 'x' + opts.exposure.toFixed(2);
    window.requestAnimationFrame(frame);
  }
  if (atmosViewerParams.get('view')) {
    viewSelect.value = atmosViewerParams.get('view');
    viewSelect.dispatchEvent(new Event('change'));
  }
  if (atmosViewerParams.get('split')) el('split').checked = true;
  if (atmosViewerModels.length > 1) el('model2').value = atmosViewerModels[1];
  document.getElementById('atmos-test').setAttribute('data-status', 'viewer');
  window.requestAnimationFrame(frame);
}

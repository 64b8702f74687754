'use strict';
// The 3D lobe: the hemisphere map's values as a surface r(ω) = value(ω) · ω, drawn with
// WebGL (diffuse shading from the surface normal, depth test), turned by dragging.
const Lobe3D = (() => {
  const VS = `attribute vec3 p; attribute vec3 n; uniform mat4 m; varying vec3 vn; varying float h;
    void main() { vn = (m * vec4(n, 0.0)).xyz; h = p.z; gl_Position = m * vec4(p, 1.0); }`;
  const FS = `precision mediump float; varying vec3 vn; varying float h; uniform vec3 c;
    void main() { float d = abs(dot(normalize(vn), normalize(vec3(0.3, 0.5, 0.8))));
      gl_FragColor = vec4(c * (0.25 + 0.75 * d), 1.0); }`;

  function compile(gl, type, src) {
    const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }

  function create(canvas) {
    const gl = canvas.getContext('webgl', { antialias: true, preserveDrawingBuffer: true });
    if (!gl) return null;
    const prog = gl.createProgram();
    gl.attachShader(prog, compile(gl, gl.VERTEX_SHADER, VS));
    gl.attachShader(prog, compile(gl, gl.FRAGMENT_SHADER, FS));
    gl.linkProgram(prog);
    const state = { gl, prog, yaw: 0.35, pitch: 0.45, count: 0, buffers: null, color: [0.2, 0.45, 0.8], canvas };
    let drag = null;
    canvas.addEventListener('mousedown', e => { drag = [e.clientX, e.clientY]; });
    window.addEventListener('mouseup', () => { drag = null; });
    window.addEventListener('mousemove', e => {
      if (!drag) return;
      state.yaw += (e.clientX - drag[0]) * 0.01;
      state.pitch = Math.min(Math.max(state.pitch + (e.clientY - drag[1]) * 0.01, 0.05), 1.55);
      drag = [e.clientX, e.clientY];
      draw(state);
    });
    return state;
  }

  // values: n*n over the projected disk (row 0 at y = −1), NaN outside; scaled so the
  // largest value is 1.
  function setData(state, n, values, color) {
    const gl = state.gl;
    let max = 0;
    for (const v of values) if (Number.isFinite(v)) max = Math.max(max, v);
    if (!(max > 0)) max = 1;
    const point = (r, c) => {
      const k = r * n + c, v = values[k];
      if (!Number.isFinite(v)) return null;
      const x = -1 + (c + 0.5) * 2 / n, y = -1 + (r + 0.5) * 2 / n, z = Math.sqrt(Math.max(0, 1 - x * x - y * y));
      const s = Math.max(v, 0) / max;
      return [s * x, s * y, s * z];
    };
    const pos = [], nor = [];
    const push = (a, b, d) => {
      const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]], w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
      const nn = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
      for (const q of [a, b, d]) { pos.push(...q); nor.push(...nn); }
    };
    for (let r = 0; r + 1 < n; r++) for (let c = 0; c + 1 < n; c++) {
      const a = point(r, c), b = point(r, c + 1), d = point(r + 1, c), e = point(r + 1, c + 1);
      if (a && b && d) push(a, b, d);
      if (b && e && d) push(b, e, d);
    }
    if (!state.buffers) state.buffers = [gl.createBuffer(), gl.createBuffer()];
    gl.bindBuffer(gl.ARRAY_BUFFER, state.buffers[0]); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(pos), gl.STATIC_DRAW);
    gl.bindBuffer(gl.ARRAY_BUFFER, state.buffers[1]); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(nor), gl.STATIC_DRAW);
    state.count = pos.length / 3;
    if (color) state.color = color;
    draw(state);
  }

  function matrix(state, aspect) {
    const cy = Math.cos(state.yaw), sy = Math.sin(state.yaw), cp = Math.cos(state.pitch), sp = Math.sin(state.pitch);
    // Turn about z (yaw), tilt about x (pitch: 0 looks from the side, π/2 from above), scale.
    const s = 0.9;
    const rz = [cy, sy, 0, -sy, cy, 0, 0, 0, 1];
    const rx = [1, 0, 0, 0, sp, cp, 0, -cp, sp];
    const m3 = [0, 0, 0, 0, 0, 0, 0, 0, 0];
    for (let i = 0; i < 3; i++) for (let j = 0; j < 3; j++) for (let k = 0; k < 3; k++) m3[i * 3 + j] += rx[i * 3 + k] * rz[k * 3 + j];
    // Column-major 4×4 with the view's z into depth and a downward shift of the lobe.
    return new Float32Array([
      s * m3[0] / aspect, s * m3[3], -0.5 * m3[6], 0,
      s * m3[1] / aspect, s * m3[4], -0.5 * m3[7], 0,
      s * m3[2] / aspect, s * m3[5], -0.5 * m3[8], 0,
      0, -0.55, 0, 1]);
  }

  function draw(state) {
    const { gl, prog, canvas } = state;
    const dpr = window.devicePixelRatio || 1;
    canvas.width = Math.round(canvas.clientWidth * dpr); canvas.height = Math.round(canvas.clientHeight * dpr);
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(1, 1, 1, 1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    if (!state.count) return;
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(prog);
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, 'm'), false, matrix(state, canvas.width / canvas.height));
    gl.uniform3fv(gl.getUniformLocation(prog, 'c'), state.color);
    for (const [k, name] of [[0, 'p'], [1, 'n']]) {
      const loc = gl.getAttribLocation(prog, name);
      gl.bindBuffer(gl.ARRAY_BUFFER, state.buffers[k]);
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
    }
    gl.drawArrays(gl.TRIANGLES, 0, state.count);
  }

  return { create, setData, draw };
})();

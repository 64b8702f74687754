'use strict';
// The explorer's other panels, around the views of app.js: the live preview (progressive
// path-traced passes, averaged here), the 3D lobe, the glint patch NDF, the fit of a
// measured file, and the validation checks. They read and extend `window.explorer`.
const Panels = (() => {
  const app = window.explorer;

  async function postJson(view, body) {
    const r = await fetch('/api/' + view, { method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify(body) });
    const v = await r.json();
    if (!r.ok) throw new Error(v.error);
    return v;
  }

  // ---- live preview ------------------------------------------------------------------------
  const preview = { width: 192, height: 144, spp: 1, maxPasses: 96, passes: 0, sum: null, key: null, running: false, error: null, timer: null };
  app.preview = preview;

  function previewMaterial() {
    const m = app.materials[app.active];
    return m ? app.textOf(m) : null;
  }

  function restartPreview() {
    preview.key = null;
    clearTimeout(preview.timer);
    preview.timer = setTimeout(previewStep, 30);
  }

  async function previewStep() {
    preview.timer = null;
    if (preview.running) return;
    const key = previewMaterial();
    const canvas = document.getElementById('preview-plot');
    if (!key || key.startsWith('measured:')) {
      preview.key = key; preview.passes = 0;
      message(canvas, key ? 'the preview renders materials written as TOML tables' : '');
      return;
    }
    if (key !== preview.key) {
      preview.key = key; preview.passes = 0; preview.error = null;
      preview.sum = new Float64Array(preview.width * preview.height * 3);
    }
    if (preview.passes >= preview.maxPasses || preview.error) return;
    // The views come first: a pass waits while they are being computed.
    if (!app.settled()) { preview.timer = setTimeout(previewStep, 40); return; }
    preview.running = true;
    try {
      const f = await app.post('preview', 'preview', { material: key, width: preview.width, height: preview.height, spp: preview.spp, pass: preview.passes + 1 }, true);
      if (preview.key === key) {
        const n = preview.width * preview.height, d = f.data;
        for (let k = 0; k < n; k++) { preview.sum[3 * k] += d.r[k]; preview.sum[3 * k + 1] += d.g[k]; preview.sum[3 * k + 2] += d.b[k]; }
        preview.passes++;
        preview.rate = f.msamples_per_second;
        drawPreview();
      }
    } catch (e) {
      if (e.name !== 'AbortError' && e.message !== 'cancelled') { preview.error = e.message; message(canvas, e.message); }
    } finally {
      preview.running = false;
    }
    preview.timer = setTimeout(previewStep, 0);
  }

  function srgb(v) {
    v = Math.max(0, v);
    const c = v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
    return Math.round(255 * Math.min(1, c));
  }

  function drawPreview() {
    const canvas = document.getElementById('preview-plot');
    const { width: w, height: h } = preview;
    const ctx = canvas.getContext('2d');
    canvas.width = w; canvas.height = h;
    const img = ctx.createImageData(w, h), k = 1 / preview.passes;
    for (let i = 0; i < w * h; i++) {
      for (let c = 0; c < 3; c++) img.data[4 * i + c] = srgb(preview.sum[3 * i + c] * k);
      img.data[4 * i + 3] = 255;
    }
    ctx.putImageData(img, 0, 0);
    document.getElementById('preview-info').textContent =
      `${preview.passes * preview.spp} spp` + (preview.rate ? ` · ${preview.rate.toFixed(1)} Msamples/s` : '');
  }

  function message(canvas, text) {
    const ctx = canvas.getContext('2d');
    if (!ctx) { canvas.title = text; return; }  // a WebGL canvas has no 2D context
    canvas.width = canvas.clientWidth; canvas.height = canvas.clientHeight;
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    ctx.fillStyle = '#b00020'; ctx.font = '12px system-ui, sans-serif';
    wrap(ctx, text, 8, 18, canvas.width - 16);
  }

  function wrap(ctx, text, x, y, width) {
    let line = '';
    for (const word of String(text).split(' ')) {
      if (ctx.measureText(line + word).width > width && line) { ctx.fillText(line, x, y); y += 15; line = ''; }
      line += word + ' ';
    }
    ctx.fillText(line, x, y);
  }

  // ---- 3D lobe -------------------------------------------------------------------------------
  let lobe = null;
  function hemisphereDrawn() {
    const canvas = document.getElementById('lobe-plot');
    if (!lobe) {
      try { lobe = Lobe3D.create(canvas); } catch (e) { lobe = null; app.errors.push('WebGL: ' + e.message); }
      if (!lobe) { message(canvas, 'WebGL is not available in this browser'); return; }
    }
    const h = app.drawn.hemisphere, m = app.materials[app.active];
    const hex = m ? m.color : '#1f77b4';
    const rgb = [1, 3, 5].map(i => parseInt(hex.slice(i, i + 2), 16) / 255);
    Lobe3D.setData(lobe, h.n, h.values, rgb);
    app.drawn.lobe = { triangles: lobe.count / 3 };
  }

  // ---- patch NDF (glints) ----------------------------------------------------------------------
  let patchNdfKey = null;
  async function updatePatchNdf() {
    const m = app.materials[app.active];
    const fig = document.getElementById('patch-ndf-figure');
    if (!m || m.type !== 'glint') { fig.hidden = true; patchNdfKey = null; return; }
    fig.hidden = false;
    // Only a change of the selected glint material recomputes its map.
    if (app.textOf(m) === patchNdfKey) return;
    patchNdfKey = app.textOf(m);
    try {
      const f = await app.post('patch-ndf', 'active', { material: app.textOf(m), n: 128, supersample: 2 });
      app.data.patchNdf = f;
      Plots.heatmap(document.getElementById('patch-ndf-plot'), f.n, f.data.d, { log: true, label: 'D_P (1/sr)' });
      document.getElementById('patch-ndf-info').textContent =
        `footprint σ = ${f.footprint_size.slice(0, 2).join(', ')} texels at uv ${f.footprint_center.join(', ')} · ∫D_P cos θh dωh = ${f.integral.toFixed(4)}`;
    } catch (e) {
      if (e.name !== 'AbortError' && e.message !== 'cancelled') { document.getElementById('patch-ndf-info').textContent = e.message; patchNdfKey = null; }
    }
  }

  // ---- fit ---------------------------------------------------------------------------------------
  const FIT_DISTRIBUTIONS = { il: ['beckmann', 'ggx', 'gaussian'], plastic: ['beckmann', 'ggx'], kelemen: ['ward'] };

  function refreshFitChoices() {
    const measured = app.materials.filter(m => m.kind === 'measured');
    const fig = document.getElementById('fit-figure');
    fig.hidden = measured.length === 0;
    const sel = document.getElementById('fit-measured');
    const keep = sel.value;
    sel.replaceChildren(...measured.map(m => { const o = document.createElement('option'); o.value = m.measuredId; o.textContent = m.name; return o; }));
    if (measured.some(m => String(m.measuredId) === keep)) sel.value = keep;
    const model = document.getElementById('fit-model').value;
    const dist = document.getElementById('fit-distribution');
    const was = dist.value;
    dist.replaceChildren(...FIT_DISTRIBUTIONS[model].map(d => { const o = document.createElement('option'); o.value = d; o.textContent = d; return o; }));
    if (FIT_DISTRIBUTIONS[model].includes(was)) dist.value = was;
    document.getElementById('fit-il-evaluation').disabled = model !== 'il';
  }

  async function runFit() {
    const info = document.getElementById('fit-info');
    const button = document.getElementById('fit-run');
    const model = document.getElementById('fit-model').value;
    const body = {
      measured: Number(document.getElementById('fit-measured').value),
      model,
      distribution: model === 'kelemen' ? 'beckmann' : document.getElementById('fit-distribution').value,
      il_evaluation: document.getElementById('fit-il-evaluation').value,
      error: document.getElementById('fit-error').value,
    };
    button.disabled = true; info.textContent = 'fitting…'; app.fitting = true;
    try {
      const f = await app.post('fit', 'fit', body, true);
      app.data.fit = f;
      const params = f.parameters.map(p => `${p.name} = ${+p.value.toPrecision(5)}${p.unit ? ' ' + p.unit : ''}`).join(', ');
      info.textContent = `${f.family}: ${params} · rms relative error ${(100 * f.rms_relative_error).toFixed(1)} % · ${f.seconds.toFixed(1)} s${f.converged ? '' : ' (not converged)'}`;
      document.getElementById('fit-material').value = f.material || '';
      drawFit(f);
    } catch (e) {
      info.textContent = 'error: ' + e.message;
    } finally {
      button.disabled = false; app.fitting = false;
    }
  }

  function drawFit(f) {
    const x = Array.from(f.data.theta_o);
    const colours = { r: '#d62728', g: '#2ca02c', b: '#1f77b4' };
    const residual = [];
    [30, 70].forEach((t, k) => {
      const series = [];
      for (const c of ['r', 'g', 'b']) {
        const measured = Array.from(f.data[`measured_${t}_${c}`]), fitted = Array.from(f.data[`fitted_${t}_${c}`]);
        series.push({ x, y: measured, color: colours[c], points: true });
        series.push({ x, y: fitted, color: colours[c] });
        if (c === 'g') residual.push({ x, y: fitted.map((v, i) => (measured[i] > 0 && v > 0 ? Math.log(v / measured[i]) : NaN)), color: k ? '#9467bd' : '#ff7f0e', dash: k === 1 });
      }
      Plots.lineChart(document.getElementById(`fit-plot-${t}`), series, { xlabel: `θo (degrees), θi = ${t}°: points measured, lines fitted`, ylabel: 'f (1/sr)', log: true, xmin: -90, xmax: 90 });
    });
    Plots.lineChart(document.getElementById('fit-residual'), residual, { xlabel: 'θo (degrees): ln(fitted / measured), green; solid 30°, dashed 70°', ylabel: 'ln ratio', log: false, xmin: -90, xmax: 90 });
  }

  async function addFitted() {
    const text = document.getElementById('fit-material').value;
    if (text) await app.addMaterialFromText(text);
  }

  // ---- measured files ------------------------------------------------------------------------
  async function loadMeasured(file) {
    const info = document.getElementById('measured-info');
    info.textContent = 'loading ' + file.name + '…';
    try {
      const r = await fetch('/api/measured', { method: 'POST', headers: { 'x-file-name': encodeURIComponent(file.name) }, body: await file.arrayBuffer() });
      const v = await r.json();
      if (!r.ok) throw new Error(v.error);
      app.addMeasured(v);
      info.textContent = `${v.name}: ${v.valid_bins} valid bins`;
    } catch (e) {
      info.textContent = 'error: ' + e.message;
    }
  }

  // ---- validation ----------------------------------------------------------------------------
  async function runValidation() {
    const m = app.materials[app.active];
    const out = document.getElementById('validate-lines');
    const summary = document.getElementById('validate-summary');
    if (!m) return;
    summary.textContent = 'running the checks of ' + (m.name || m.type) + '…';
    out.replaceChildren();
    app.validating = true;
    try {
      const v = await postJson('validate', { material: app.textOf(m), samples: Number(document.getElementById('validate-samples').value) });
      app.data.validation = v;
      summary.textContent = v.material + ': ' + v.summary;
      for (const l of v.lines) {
        const row = document.createElement('tr');
        row.className = l.verdict.toLowerCase();
        for (const t of [l.verdict, l.subject === v.material ? '' : l.subject, l.name, l.figure]) {
          const td = document.createElement('td'); td.textContent = t; row.append(td);
        }
        out.append(row);
      }
    } catch (e) {
      summary.textContent = 'error: ' + e.message;
    } finally {
      app.validating = false;
    }
  }

  function bind() {
    document.getElementById('fit-model').addEventListener('change', refreshFitChoices);
    document.getElementById('fit-run').addEventListener('click', runFit);
    document.getElementById('fit-add').addEventListener('click', addFitted);
    document.getElementById('fit-copy').addEventListener('click', () => {
      const t = document.getElementById('fit-material'); t.select();
      if (navigator.clipboard) navigator.clipboard.writeText(t.value).catch(() => document.execCommand('copy')); else document.execCommand('copy');
    });
    document.getElementById('measured-file').addEventListener('change', e => { if (e.target.files[0]) loadMeasured(e.target.files[0]); });
    document.getElementById('validate-run').addEventListener('click', runValidation);
  }

  return {
    bind,
    // Called by app.js.
    hemisphereDrawn,
    materialsChanged() { refreshFitChoices(); restartPreview(); updatePatchNdf(); },
    refreshFitChoices,
  };
})();
window.Panels = Panels;

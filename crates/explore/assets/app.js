'use strict';
// facette explore: the app. Materials are edited with controls generated from the
// server's schema (the same descriptions the TOML grammar is tested against); every change
// re-evaluates the views on the server (f64, the bsdf crate), cancelling stale requests.
// `window.explorer` exposes the state and the numbers drawn, for tests and the console.

const app = {
  schema: null,
  types: {},
  materials: [],
  active: 0,
  nextId: 1,
  view: { thetaI: 30, phiI: 0, quantity: 'f', scale: 'linear', samples: 64, hemiN: 128, albedoSamples: 4096 },
  data: { slice: {}, hemisphere: null, albedo: {} },
  inflight: {},
  pending: 0,
  timer: null,
  changedAt: null,
  latency: {},
  errors: [],
};
window.explorer = app;

const ALBEDO_ANGLES = [0, 5, 10, 15, 20, 25, 30, 35, 40, 45, 50, 55, 60, 65, 70, 75, 80, 85, 89];

// ---- TOML values -------------------------------------------------------------------------

function tomlValue(v) {
  if (Array.isArray(v)) return '[' + v.map(tomlValue).join(', ') + ']';
  if (typeof v === 'number') {
    if (Number.isNaN(v)) return 'nan';
    if (!Number.isFinite(v)) return v > 0 ? 'inf' : '-inf';
    return String(v);
  }
  if (typeof v === 'boolean') return String(v);
  return JSON.stringify(String(v));
}

// What a request names the material by: its TOML table, or `measured:ID`.
function textOf(m) {
  return m.kind === 'measured' ? m.text : tomlText(m);
}
app.textOf = textOf;

function tomlText(m) {
  if (m.kind === 'measured') return m.text;
  const keys = Object.keys(m.table);
  const order = app.types[m.type].keys;
  keys.sort((a, b) => order.indexOf(a) - order.indexOf(b));
  return '{' + ['type = ' + tomlValue(m.type)].concat(keys.map(k => k + ' = ' + tomlValue(m.table[k]))).join(', ') + '}';
}

// Reads what a user typed in a text field: a number, an array of numbers, or a string.
function parseLoose(text) {
  const t = text.trim();
  if (t === '') return undefined;
  if (/^\[.*\]$/.test(t)) {
    const parts = t.slice(1, -1).split(',').map(s => s.trim()).filter(s => s !== '');
    return parts.map(s => (Number.isNaN(Number(s)) ? s : Number(s)));
  }
  if (/^[-+]?(\d|\.\d|inf|nan)/i.test(t) && !Number.isNaN(Number(t.replace(/^([-+]?)inf$/i, '$1Infinity')))) {
    return Number(t.replace(/^([-+]?)inf$/i, '$1Infinity'));
  }
  if (/^nan$/i.test(t)) return NaN;
  return t.replace(/^"(.*)"$/, '$1');
}

// ---- the schema's rules (as recipe::schema applies them) ---------------------------------

function valueOf(m, key) {
  if (key in m.table) { const v = m.table[key]; return typeof v === 'string' ? v : tomlValue(v); }
  const p = app.types[m.type].params.find(p => p.key === key && p.default !== null);
  return p ? p.default.replace(/^"(.*)"$/, '$1') : null;
}

function applies(m, p) {
  return p.when.every(w => {
    const v = valueOf(m, w.key);
    return v !== null && (w.any_of.length === 0 || w.any_of.includes(v));
  });
}

function applying(m, key) {
  return app.types[m.type].params.find(p => p.key === key && applies(m, p)) || null;
}

function startValue(p) {
  return parseLoose(p.start);
}

// As recipe::schema's retain_applicable: keys that no longer apply, and choices the entry
// that now applies does not offer, are dropped.
function retainApplicable(m) {
  for (;;) {
    const stale = Object.keys(m.table).filter(k => {
      const p = applying(m, k);
      return !p || (p.kind === 'choice' && typeof m.table[k] === 'string' && !p.values.includes(m.table[k]));
    });
    if (!stale.length) return;
    stale.forEach(k => delete m.table[k]);
  }
}

function fillRequired(m) {
  const params = app.types[m.type].params;
  for (const p of params) {
    if (!applies(m, p) || p.key in m.table) continue;
    const alternative = p.excludes.some(k => k in m.table) || params.some(q => q.excludes.includes(p.key) && q.key in m.table);
    const needed = params.some(q => q.needs.includes(p.key) && q.key in m.table && applies(m, q));
    if ((p.required && !alternative) || needed) m.table[p.key] = startValue(p);
  }
}

function setKey(m, key, value) {
  const p = applying(m, key);
  if (value === undefined) { delete m.table[key]; }
  else {
    m.table[key] = value;
    if (p) p.excludes.forEach(k => delete m.table[k]);
    // Exclusion goes both ways: giving `alpha` removes a `preset` that excludes it.
    app.types[m.type].params.forEach(q => { if (q.excludes.includes(key) && q.key in m.table && q.key !== key) delete m.table[q.key]; });
  }
  retainApplicable(m);
  fillRequired(m);
}

// ---- materials -----------------------------------------------------------------------------

function newMeasured(v) {
  return { kind: 'measured', id: app.nextId++, measuredId: v.id, type: 'measured', name: v.name, text: v.text, validBins: v.valid_bins, table: {}, color: Plots.PALETTE[(app.nextId - 2) % Plots.PALETTE.length], error: null, describe: '', stochastic: false };
}

app.addMeasured = v => {
  app.materials.push(newMeasured(v));
  app.active = app.materials.length - 1;
  changed(app.materials[app.active]);
};

app.addMaterialFromText = async text => {
  const x = await materialFromText(text);
  app.materials.push(newMaterial(x.type, x.table));
  app.active = app.materials.length - 1;
  changed(app.materials[app.active]);
};

function newMaterial(type, table) {
  const m = { id: app.nextId++, type, table: table || {}, color: Plots.PALETTE[(app.nextId - 2) % Plots.PALETTE.length], error: null, describe: '', stochastic: false };
  retainApplicable(m);
  fillRequired(m);
  return m;
}

async function materialFromText(text) {
  if (text.trim().startsWith('measured:')) throw new Error('a measured file is opened with “load MERL file…”');
  const r = await fetch('/api/material', { method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ material: text }) });
  const body = await r.json();
  if (!r.ok) throw new Error(body.error);
  const table = Object.assign({}, body.table);
  const type = table.type; delete table.type;
  if (!app.types[type]) throw new Error(`type "${type}" has no controls in this page`);
  return { type, table, describe: body.describe, stochastic: body.stochastic };
}

function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (k === 'dataset') Object.assign(e.dataset, v);
    else if (v !== undefined && v !== null && v !== false) e.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children) if (c !== null && c !== undefined) e.append(c);
  return e;
}

// A slider's span: the range, narrowed to where values usually are when it spans more than
// ten times the starting value; logarithmic keys move the exponent.
function sliderSpan(p) {
  const r = p.range;
  let lo = r.lo === null ? -1e3 : r.lo, hi = r.hi === null ? 1e3 : r.hi;
  const s = Number(p.start);
  if (p.log) { lo = Math.max(lo, hi * 1e-8, 1e-12); return { lo: Math.log10(lo), hi: Math.log10(hi), log: true }; }
  if (s > 0 && hi > 10 * s) hi = Math.max(1, 4 * s);
  return { lo, hi, log: false };
}

function paramRow(m, p, index) {
  const key = p.key;
  const set = key in m.table;
  const value = set ? m.table[key] : (p.default !== null ? parseLoose(p.default) : startValue(p));
  const data = { material: String(index), key };
  const optional = !p.required;
  const row = el('div', { class: 'param' + (set || p.required ? '' : ' off'), title: p.doc + (p.range ? ' — range ' + p.range.text : '') + (p.default !== null ? ' — default ' + p.default : '') });
  row.append(optional
    ? el('input', { type: 'checkbox', checked: set, title: 'give this key (unchecked: its default)', dataset: { ...data, role: 'set' }, onchange: e => { setKey(m, key, e.target.checked ? value : undefined); changed(m); } })
    : el('span'));
  row.append(el('label', {}, key + (p.unit ? ' (' + p.unit + ')' : '')));
  const commit = v => { setKey(m, key, v); changed(m); };
  let widget, text;
  if (p.kind === 'choice') {
    widget = el('select', { dataset: { ...data, role: 'select' }, onchange: e => commit(e.target.value) },
      ...p.values.map(v => el('option', { value: v, selected: v === value }, v)));
    text = el('span', { class: 'value' });
  } else if (p.kind === 'number' || (p.kind === 'spectrum' && !Array.isArray(value))) {
    const span = sliderSpan(p.kind === 'spectrum' ? { range: p.range, start: p.start, log: false } : p);
    const toSlider = v => (span.log ? Math.log10(Math.max(v, 1e-300)) : v);
    const fromSlider = s => (span.log ? Math.pow(10, s) : s);
    widget = el('input', { type: 'range', min: span.lo, max: span.hi, step: (span.hi - span.lo) / 1000, value: toSlider(Number(value)), dataset: { ...data, role: 'slider' },
      oninput: e => { const v = +fromSlider(+e.target.value).toPrecision(4); text.value = String(v); commit(v); } });
    text = el('input', { type: 'text', value: tomlValue(value), dataset: { ...data, role: 'input' }, onchange: e => commit(parseLoose(e.target.value)) });
  } else {
    widget = el('input', { type: 'text', value: value === undefined ? '' : (typeof value === 'string' ? value : tomlValue(value)), dataset: { ...data, role: 'input' },
      onchange: e => { const v = p.kind === 'path' ? e.target.value : parseLoose(e.target.value); commit(v); } });
    text = el('span', { class: 'value' });
  }
  row.append(el('div', { class: 'widget' }, widget), text);
  return row;
}

function renderMaterials() {
  const box = document.getElementById('materials');
  box.replaceChildren();
  app.materials.forEach((m, index) => {
    if (m.kind === 'measured') { box.append(measuredCard(m, index)); return; }
    const ty = app.types[m.type];
    const card = el('div', { class: 'material' + (index === app.active ? ' active' : ''), style: '--color:' + m.color, dataset: { material: String(index) },
      onclick: () => { if (app.active !== index) { app.active = index; renderMaterials(); schedule(['hemisphere']); if (window.Panels) Panels.materialsChanged(); } } });
    const typeSelect = el('select', { dataset: { material: String(index), role: 'type' }, onchange: e => {
      const t = app.types[e.target.value];
      Object.assign(m, newMaterial(t.name, {}), { id: m.id, color: m.color });
      // Another change of type may answer first: only the type still chosen takes its example.
      materialFromText(t.example).then(x => {
        if (m.type !== x.type || !app.materials.includes(m)) return;
        m.table = x.table; retainApplicable(m); fillRequired(m); changed(m);
      }).catch(err => { m.error = err.message; renderMaterials(); });
    } }, ...app.schema.types.map(t => el('option', { value: t.name, selected: t.name === m.type }, t.name)));
    card.append(el('div', { class: 'top' }, typeSelect,
      app.materials.length > 1 ? el('button', { title: 'remove', dataset: { material: String(index), role: 'remove' }, onclick: e => { e.stopPropagation(); removeMaterial(index); } }, '×') : null));
    card.append(el('div', { class: 'summary' }, ty.summary));
    const seen = new Set();
    for (const key of ty.keys) {
      if (seen.has(key)) continue; seen.add(key);
      const p = applying(m, key);
      if (p) card.append(paramRow(m, p, index));
    }
    const area = el('textarea', { spellcheck: 'false', dataset: { material: String(index), role: 'toml' } });
    area.value = tomlText(m);
    card.append(area);
    card.append(el('div', { class: 'buttons' },
      el('button', { dataset: { material: String(index), role: 'apply' }, onclick: () => applyText(m, area.value) }, 'apply text'),
      el('button', { dataset: { material: String(index), role: 'copy' }, onclick: () => copyText(area) }, 'copy TOML')));
    card.append(el('div', { class: 'error', dataset: { material: String(index), role: 'error' } }, m.error || ''));
    card.append(el('div', { class: 'describe' }, m.describe || ''));
    box.append(card);
  });
  document.getElementById('hemi-material').textContent = 'material ' + (app.active + 1);
}

// Removes material `index`; the selected material stays selected (or the one after it).
function removeMaterial(index) {
  app.materials.splice(index, 1);
  if (index < app.active) app.active--;
  app.active = Math.max(0, Math.min(app.active, app.materials.length - 1));
  renderMaterials();
  schedule();
  if (window.Panels) Panels.materialsChanged();
}

function measuredCard(m, index) {
  const card = el('div', { class: 'material' + (index === app.active ? ' active' : ''), style: '--color:' + m.color, dataset: { material: String(index) },
    onclick: () => { if (app.active !== index) { app.active = index; renderMaterials(); schedule(['hemisphere']); if (window.Panels) Panels.materialsChanged(); } } });
  card.append(el('div', { class: 'top' }, el('strong', {}, 'measured: ' + m.name),
    el('button', { title: 'remove', dataset: { material: String(index), role: 'remove' }, onclick: e => { e.stopPropagation(); removeMaterial(index); } }, '×')));
  card.append(el('div', { class: 'summary' }, `MERL file, ${m.validBins} valid bins; nearest-bin values, sampled cosine-weighted (fit it in the Fit panel)`));
  card.append(el('div', { class: 'error', dataset: { material: String(index), role: 'error' } }, m.error || ''));
  card.append(el('div', { class: 'describe' }, m.describe || ''));
  return card;
}

async function applyText(m, text) {
  try {
    const x = await materialFromText(text);
    Object.assign(m, { type: x.type, table: x.table, error: null });
    changed(m);
  } catch (e) {
    m.error = e.message;
    renderMaterials();
  }
}

function copyText(area) {
  area.select();
  if (navigator.clipboard) navigator.clipboard.writeText(area.value).catch(() => document.execCommand('copy'));
  else document.execCommand('copy');
}

function changed(m) {
  app.changedAt = performance.now();
  m.error = null;
  // Controls are rebuilt unless the user is dragging one of them (a rebuild would drop the drag).
  const focused = document.activeElement;
  const dragging = focused && focused.type === 'range' && focused.dataset.key;
  if (dragging) {
    const area = document.querySelector(`textarea[data-material="${app.materials.indexOf(m)}"]`);
    if (area) area.value = tomlText(m);
    const sig = signature(m);
    if (sig !== m.signature) renderMaterials();
    m.signature = sig;
  } else {
    renderMaterials();
    m.signature = signature(m);
  }
  schedule();
  if (window.Panels) Panels.materialsChanged();
}

function signature(m) {
  if (m.kind === 'measured') return 'measured ' + m.text;
  return m.type + '|' + app.types[m.type].keys.map(k => { const p = applying(m, k); return p ? k + (k in m.table ? '+' : '-') + p.kind : ''; }).join(',');
}

// ---- requests ------------------------------------------------------------------------------

function schedule(views) {
  views = views || ['slice', 'hemisphere', 'albedo'];
  app.scheduled = new Set([...(app.scheduled || []), ...views]);
  clearTimeout(app.timer);
  app.timer = setTimeout(() => { app.timer = null; const v = app.scheduled; app.scheduled = new Set(); update(v); }, 12);
}

// POSTs a view's request and decodes its frame, aborting the previous request of the same
// view and slot. Background requests (the preview's passes) do not hold `settled()`.
async function post(view, slot, body, background) {
  const id = view + ':' + slot;
  if (app.inflight[id]) app.inflight[id].abort();
  const ctl = new AbortController();
  app.inflight[id] = ctl;
  if (!background) app.pending++;
  try {
    const r = await fetch('/api/' + view, { method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify(body), signal: ctl.signal });
    if (!r.ok) {
      const e = await r.json().catch(() => ({ error: r.statusText }));
      throw new Error(e.error);
    }
    return decodeFrame(await r.arrayBuffer());
  } finally {
    if (!background) app.pending--;
    if (app.inflight[id] === ctl) delete app.inflight[id];
  }
}
app.post = post;

function decodeFrame(buf) {
  const n = new DataView(buf).getUint32(0, true);
  const head = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 4, n)));
  let at = Math.ceil((4 + n) / 8) * 8;
  const arrays = {};
  for (const a of head.arrays) { arrays[a.name] = new Float64Array(buf, at, a.len); at += 8 * a.len; }
  head.data = arrays;
  return head;
}

function baseRequest() {
  return { quantity: app.view.quantity, samples: app.view.samples, seed: 1 };
}

function update(views) {
  const t0 = app.changedAt || performance.now();
  const texts = app.materials.map(textOf);
  const jobs = [];
  if (views.has('slice')) {
    const live = new Set(app.materials.map(m => m.id));
    for (const id of Object.keys(app.data.slice)) if (!live.has(+id)) delete app.data.slice[id];
    jobs.push(Promise.allSettled(app.materials.map((m, k) =>
      post('slice', m.id, { ...baseRequest(), material: texts[k], theta_i: app.view.thetaI, points: 361 })
        .then(f => { app.data.slice[m.id] = f; m.describe = f.describe; m.stochastic = f.stochastic; })
        .catch(e => failed(m, e)))).then(() => { draw(drawSlice); draw(drawPolar); app.latency.slice = performance.now() - t0; }));
  }
  if (views.has('hemisphere') && app.materials[app.active]) {
    const m = app.materials[app.active];
    jobs.push(post('hemisphere', 'active', { ...baseRequest(), material: textOf(m), theta_i: app.view.thetaI, phi_i: app.view.phiI, n: app.view.hemiN })
      .then(f => {
        app.data.hemisphere = f;
        draw(drawHemisphere);
        app.latency.hemisphere = performance.now() - t0;
        if (window.Panels) draw(Panels.hemisphereDrawn);
      }, e => failed(m, e)));
  }
  if (views.has('albedo')) {
    jobs.push(Promise.allSettled(app.materials.map((m, k) =>
      post('albedo', m.id, { material: texts[k], angles: ALBEDO_ANGLES, samples: app.view.albedoSamples, seed: 1 })
        .then(f => { app.data.albedo[m.id] = f; })
        .catch(e => failed(m, e)))).then(() => { draw(drawAlbedo); app.latency.albedo = performance.now() - t0; }));
  }
  Promise.allSettled(jobs).then(() => {
    renderDescribe();
    status();
  });
}

// Runs a drawing function; an error in it is the page's (kept in app.errors), not the
// material's.
function draw(f) {
  try { f(); } catch (e) { app.errors.push(String(e && e.stack || e)); }
}

function failed(m, e) {
  if (e.name === 'AbortError' || e.message === 'cancelled') return;
  m.error = e.message;
  const box = document.querySelector(`.error[data-material="${app.materials.indexOf(m)}"]`);
  if (box) box.textContent = m.error;
}

function renderDescribe() {
  app.materials.forEach((m, k) => {
    const d = document.querySelectorAll('.material .describe')[k];
    if (d) d.textContent = (m.describe || '') + (m.stochastic ? ' — stochastic: ' + app.view.samples + ' estimates per value, band ±2 s.e.' : '');
    const box = document.querySelector(`.error[data-material="${k}"]`);
    if (box) box.textContent = m.error || '';
  });
}

function status() {
  const l = app.latency;
  const ms = v => (v === undefined ? '–' : Math.round(v) + ' ms');
  document.getElementById('status').textContent = `slice ${ms(l.slice)} · hemisphere ${ms(l.hemisphere)} · albedo ${ms(l.albedo)}`;
}

// Whether nothing is waiting: no debounce, no request in flight (tests wait for this).
app.settled = () => app.timer === null && app.pending === 0;

// ---- drawing ---------------------------------------------------------------------------------

function channelMean(d, prefix, k) {
  return (d[prefix + '_r'][k] + d[prefix + '_g'][k] + d[prefix + '_b'][k]) / 3;
}

function sliceSeries(band) {
  const out = [];
  for (const m of app.materials) {
    const f = app.data.slice[m.id];
    if (!f || m.error) continue;
    const d = f.data, x = Array.from(d.theta_o);
    for (const [prefix, dash] of [['reflect', false], ['transmit', true]]) {
      if (prefix === 'transmit' && !f.transmits) continue;
      const y = x.map((_, k) => channelMean(d, prefix, k));
      const e = x.map((_, k) => channelMean(d, prefix + '_err', k));
      const s = { x, y, color: m.color, dash, material: m.id, side: prefix };
      if (band && f.stochastic) { s.lo = y.map((v, k) => v - 2 * e[k]); s.hi = y.map((v, k) => v + 2 * e[k]); }
      out.push(s);
    }
  }
  return out;
}

function quantityLabel() {
  return app.view.quantity === 'f' ? 'f (1/sr), channel mean' : 'f·|cos θo| (1/sr), channel mean';
}

function drawSlice() {
  const series = sliceSeries(true);
  app.drawn = Object.assign(app.drawn || {}, { slice: series });
  Plots.lineChart(document.getElementById('slice-plot'), series, { xlabel: 'θo (degrees, signed)', ylabel: quantityLabel(), log: app.view.scale === 'log', xmin: -90, xmax: 90 });
}

function drawPolar() {
  const series = sliceSeries(false).map(s => {
    const below = s.side === 'transmit';
    const x = [], y = [];
    s.x.forEach((t, k) => { const a = t * Math.PI / 180; x.push(-Math.sin(a) * s.y[k]); y.push((below ? -1 : 1) * Math.cos(a) * s.y[k]); });
    return { x, y, color: s.color, dash: s.dash };
  });
  app.drawn.polar = series;
  const transmits = app.materials.some(m => app.data.slice[m.id] && app.data.slice[m.id].transmits);
  Plots.polarChart(document.getElementById('polar-plot'), series, { thetaI: app.view.thetaI, transmits, unit: app.view.quantity === 'f' ? '1/sr' : '' });
}

function drawHemisphere() {
  const f = app.data.hemisphere;
  if (!f) return;
  const n = f.n, d = f.data;
  const values = new Float64Array(n * n);
  for (let k = 0; k < n * n; k++) values[k] = (d.value_r[k] + d.value_g[k] + d.value_b[k]) / 3;
  const ti = f.theta_i * Math.PI / 180, pi = f.phi_i * Math.PI / 180;
  const marker = f.theta_i < 90 ? [-Math.sin(ti) * Math.cos(pi), -Math.sin(ti) * Math.sin(pi)] : null;
  app.drawn = Object.assign(app.drawn || {}, { hemisphere: { n, values } });
  Plots.heatmap(document.getElementById('hemisphere-plot'), n, values, { log: app.view.scale === 'log', marker, label: app.view.quantity === 'f' ? 'f (1/sr)' : 'f·|cos θo|' });
}

function drawAlbedo() {
  const series = [];
  for (const m of app.materials) {
    const f = app.data.albedo[m.id];
    if (!f || m.error) continue;
    const d = f.data, x = Array.from(d.theta_i);
    for (const [key, dash] of [['reflect', false], ['transmit', true]]) {
      if (key === 'transmit' && !f.transmits) continue;
      const y = Array.from(d[key]), e = Array.from(d[key + '_err']);
      series.push({ x, y, lo: y.map((v, k) => v - 2 * e[k]), hi: y.map((v, k) => v + 2 * e[k]), color: m.color, dash });
    }
  }
  app.drawn = Object.assign(app.drawn || {}, { albedo: series });
  Plots.lineChart(document.getElementById('albedo-plot'), series, { xlabel: 'θi (degrees)', ylabel: 'albedo (channel mean)', log: false, xmin: 0, xmax: 90, ymin: 0 });
}

// ---- start-up -------------------------------------------------------------------------------

function bindViewControls() {
  const bind = (id, key, parse, views, out) => {
    const input = document.getElementById(id);
    input.addEventListener('input', () => {
      app.view[key] = parse(input.value);
      if (out) document.getElementById(out).textContent = input.value + '°';
      app.changedAt = performance.now();
      schedule(views);
    });
  };
  bind('theta-i', 'thetaI', Number, ['slice', 'hemisphere'], 'theta-i-value');
  bind('phi-i', 'phiI', Number, ['hemisphere'], 'phi-i-value');
  bind('quantity', 'quantity', String, ['slice', 'hemisphere']);
  bind('samples', 'samples', v => Math.max(1, Math.min(1048576, Math.round(Number(v)) || 1)), ['slice', 'hemisphere']);
  document.getElementById('scale').addEventListener('change', e => { app.view.scale = e.target.value; drawSlice(); drawHemisphere(); });
  document.getElementById('add-material').addEventListener('click', async () => {
    const last = [...app.materials].reverse().find(m => m.kind !== 'measured');
    await app.addMaterialFromText(last ? tomlText(last) : app.schema.types[0].example);
  });
  window.addEventListener('resize', () => { drawSlice(); drawPolar(); drawHemisphere(); drawAlbedo(); });
}

async function start() {
  app.schema = await (await fetch('/api/schema')).json();
  for (const t of app.schema.types) {
    const keys = [];
    t.params.forEach(p => { if (!keys.includes(p.key)) keys.push(p.key); });
    app.types[t.name] = Object.assign({}, t, { keys });
  }
  const initial = await (await fetch('/api/initial')).json();
  for (const text of initial.materials) {
    const x = await materialFromText(text);
    app.materials.push(newMaterial(x.type, x.table));
  }
  for (const v of initial.measured) app.materials.push(newMeasured(v));
  bindViewControls();
  if (window.Panels) Panels.bind();
  renderMaterials();
  app.materials.forEach(m => { m.signature = signature(m); });
  schedule();
  if (window.Panels) Panels.materialsChanged();
}

start().catch(e => { document.getElementById('status').textContent = 'error: ' + e.message; app.errors.push(e.message); });

'use strict';
// Canvas plots for the explorer: line charts (linear or log y), polar curves with equal
// axes, and false-colour maps of the projected disk with a colour bar. No dependencies.
const Plots = (() => {
  const PALETTE = ['#1f77b4', '#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#8c564b', '#e377c2', '#17becf'];

  function setup(canvas) {
    const dpr = window.devicePixelRatio || 1;
    const w = canvas.clientWidth, h = canvas.clientHeight;
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
    const ctx = canvas.getContext('2d');
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, w, h);
    ctx.font = '11px system-ui, sans-serif';
    return { ctx, w, h };
  }

  function fmt(v) {
    if (v === 0) return '0';
    const a = Math.abs(v);
    if (a >= 1e4 || a < 1e-3) return v.toExponential(0).replace('e+', 'e');
    return String(+v.toPrecision(3));
  }

  function ticks(lo, hi, n) {
    const span = hi - lo;
    if (!(span > 0)) return [lo];
    const step0 = span / n;
    const mag = Math.pow(10, Math.floor(Math.log10(step0)));
    const step = [1, 2, 5, 10].map(m => m * mag).find(s => s >= step0);
    const out = [];
    for (let t = Math.ceil(lo / step) * step; t <= hi + 1e-9 * span; t += step) out.push(Math.abs(t) < 1e-12 * span ? 0 : t);
    return out;
  }

  function finiteRange(series, key, positive) {
    let lo = Infinity, hi = -Infinity;
    for (const s of series) for (const v of s[key] || []) {
      if (Number.isFinite(v) && (!positive || v > 0)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    }
    return [lo, hi];
  }

  // series: [{x, y, lo?, hi?, color, dash}]; opts: {xlabel, ylabel, log, xmin, xmax, ymin}
  function lineChart(canvas, series, opts) {
    const { ctx, w, h } = setup(canvas);
    const m = { l: 58, r: 12, t: 10, b: 34 };
    const pw = w - m.l - m.r, ph = h - m.t - m.b;
    let [xlo, xhi] = finiteRange(series, 'x');
    if (opts.xmin !== undefined) { xlo = opts.xmin; xhi = opts.xmax; }
    const all = series.map(s => ({ y: s.y.concat(s.hi || []) }));
    let [ylo, yhi] = finiteRange(all, 'y', opts.log);
    if (!Number.isFinite(ylo)) { ylo = opts.log ? 1e-3 : 0; yhi = 1; }
    if (opts.log) {
      ylo = Math.max(ylo, yhi * 1e-6);
      ylo = Math.log10(ylo); yhi = Math.log10(yhi);
      if (yhi - ylo < 1) { ylo -= 0.5; yhi += 0.5; }
    } else {
      ylo = Math.min(0, opts.ymin !== undefined ? opts.ymin : ylo);
      if (yhi <= ylo) yhi = ylo + 1;
      yhi += 0.05 * (yhi - ylo);
    }
    const X = x => m.l + (x - xlo) / (xhi - xlo) * pw;
    const Y = y => {
      const v = opts.log ? Math.log10(Math.max(y, 1e-300)) : y;
      return m.t + ph - (Math.min(Math.max(v, ylo - 1), yhi + 1) - ylo) / (yhi - ylo) * ph;
    };
    ctx.strokeStyle = '#ddd'; ctx.fillStyle = '#444'; ctx.lineWidth = 1;
    for (const t of ticks(xlo, xhi, 6)) {
      ctx.beginPath(); ctx.moveTo(X(t), m.t); ctx.lineTo(X(t), m.t + ph); ctx.stroke();
      ctx.textAlign = 'center'; ctx.fillText(fmt(t), X(t), m.t + ph + 13);
    }
    const yt = opts.log ? ticks(Math.ceil(ylo), Math.floor(yhi), 6).filter(Number.isInteger) : ticks(ylo, yhi, 6);
    for (const t of yt) {
      const py = opts.log ? Y(Math.pow(10, t)) : Y(t);
      ctx.beginPath(); ctx.moveTo(m.l, py); ctx.lineTo(m.l + pw, py); ctx.stroke();
      ctx.textAlign = 'right'; ctx.fillText(opts.log ? '1e' + t : fmt(t), m.l - 4, py + 4);
    }
    ctx.strokeStyle = '#888'; ctx.strokeRect(m.l, m.t, pw, ph);
    ctx.textAlign = 'center'; ctx.fillText(opts.xlabel || '', m.l + pw / 2, h - 4);
    ctx.save(); ctx.translate(12, m.t + ph / 2); ctx.rotate(-Math.PI / 2); ctx.fillText(opts.ylabel || '', 0, 0); ctx.restore();
    ctx.save(); ctx.beginPath(); ctx.rect(m.l, m.t, pw, ph); ctx.clip();
    for (const s of series) {
      if (s.lo && s.hi) {
        ctx.fillStyle = s.color + '33'; ctx.beginPath();
        s.x.forEach((x, k) => { const p = [X(x), Y(s.hi[k])]; k ? ctx.lineTo(...p) : ctx.moveTo(...p); });
        for (let k = s.x.length - 1; k >= 0; k--) ctx.lineTo(X(s.x[k]), Y(Math.max(s.lo[k], opts.log ? 1e-300 : -Infinity)));
        ctx.fill();
      }
      if (s.points) {
        ctx.fillStyle = s.color;
        s.x.forEach((x, k) => {
          const y = s.y[k];
          if (Number.isFinite(y) && (!opts.log || y > 0)) { ctx.beginPath(); ctx.arc(X(x), Y(y), 1.8, 0, 2 * Math.PI); ctx.fill(); }
        });
        continue;
      }
      ctx.strokeStyle = s.color; ctx.lineWidth = 1.6; ctx.setLineDash(s.dash ? [5, 4] : []);
      ctx.beginPath(); let pen = false;
      s.x.forEach((x, k) => {
        const y = s.y[k];
        if (!Number.isFinite(y) || (opts.log && y <= 0)) { pen = false; return; }
        pen ? ctx.lineTo(X(x), Y(y)) : ctx.moveTo(X(x), Y(y)); pen = true;
      });
      ctx.stroke();
    }
    ctx.restore(); ctx.setLineDash([]);
  }

  // series: [{x, y, color, dash}] of points in the incidence plane; equal axes, a unit
  // half-circle guide, the surface line and the light direction.
  function polarChart(canvas, series, opts) {
    const { ctx, w, h } = setup(canvas);
    let r = 0;
    for (const s of series) for (let k = 0; k < s.x.length; k++) {
      const d = Math.hypot(s.x[k], s.y[k]); if (Number.isFinite(d)) r = Math.max(r, d);
    }
    if (!(r > 0)) r = 1;
    const below = opts.transmits;
    const cx = w / 2, cy = below ? h / 2 : h - 24;
    const scale = Math.min((w / 2 - 16) / r, (below ? h / 2 - 16 : h - 40) / r);
    ctx.strokeStyle = '#ddd';
    for (const f of [0.25, 0.5, 0.75, 1]) {
      ctx.beginPath(); ctx.arc(cx, cy, f * r * scale, below ? 0 : Math.PI, 2 * Math.PI); ctx.stroke();
    }
    ctx.strokeStyle = '#888'; ctx.beginPath(); ctx.moveTo(8, cy); ctx.lineTo(w - 8, cy); ctx.stroke();
    const ti = opts.thetaI * Math.PI / 180;
    ctx.strokeStyle = '#e0a000'; ctx.setLineDash([3, 3]); ctx.beginPath(); ctx.moveTo(cx, cy);
    ctx.lineTo(cx + Math.sin(ti) * r * scale, cy - Math.cos(ti) * r * scale); ctx.stroke(); ctx.setLineDash([]);
    ctx.fillStyle = '#444'; ctx.textAlign = 'left'; ctx.fillText('radius ' + fmt(r) + ' ' + (opts.unit || ''), 8, 14);
    for (const s of series) {
      ctx.strokeStyle = s.color; ctx.lineWidth = 1.6; ctx.setLineDash(s.dash ? [5, 4] : []);
      ctx.beginPath(); let pen = false;
      for (let k = 0; k < s.x.length; k++) {
        const x = s.x[k], y = s.y[k];
        if (!Number.isFinite(x) || !Number.isFinite(y)) { pen = false; continue; }
        const px = cx + x * scale, py = cy - y * scale;
        pen ? ctx.lineTo(px, py) : ctx.moveTo(px, py); pen = true;
      }
      ctx.stroke();
    }
    ctx.setLineDash([]);
  }

  // Perceptually ordered colours (viridis-like, 5 stops).
  const STOPS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
  function colour(t) {
    t = Math.min(Math.max(t, 0), 1) * (STOPS.length - 1);
    const i = Math.min(Math.floor(t), STOPS.length - 2), f = t - i;
    return STOPS[i].map((c, k) => Math.round(c + f * (STOPS[i + 1][k] - c)));
  }

  // values: n*n row-major (row 0 at y = −1), NaN outside the disk.
  function heatmap(canvas, n, values, opts) {
    const { ctx, w, h } = setup(canvas);
    let lo = Infinity, hi = -Infinity;
    for (const v of values) if (Number.isFinite(v) && (!opts.log || v > 0)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (!Number.isFinite(lo)) { lo = 0; hi = 1; }
    if (opts.log) lo = Math.max(lo, hi * 1e-6);
    const T = v => opts.log ? (Math.log(v / lo) / Math.log(hi / lo || 10)) : (hi > lo ? (v - lo) / (hi - lo) : 0.5);
    const img = ctx.createImageData(n, n);
    for (let r = 0; r < n; r++) for (let c = 0; c < n; c++) {
      const v = values[r * n + c], o = ((n - 1 - r) * n + c) * 4;
      if (!Number.isFinite(v)) { img.data[o + 3] = 0; continue; }
      const [R, G, B] = colour(opts.log && v <= 0 ? 0 : T(v));
      img.data[o] = R; img.data[o + 1] = G; img.data[o + 2] = B; img.data[o + 3] = 255;
    }
    const off = document.createElement('canvas'); off.width = n; off.height = n;
    off.getContext('2d').putImageData(img, 0, 0);
    const size = Math.min(w - 90, h - 10), x0 = 8, y0 = (h - size) / 2;
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(off, x0, y0, size, size);
    ctx.strokeStyle = '#ffffff88';
    for (const t of [30, 60]) { ctx.beginPath(); ctx.arc(x0 + size / 2, y0 + size / 2, Math.sin(t * Math.PI / 180) * size / 2, 0, 2 * Math.PI); ctx.stroke(); }
    ctx.strokeStyle = '#888'; ctx.beginPath(); ctx.arc(x0 + size / 2, y0 + size / 2, size / 2, 0, 2 * Math.PI); ctx.stroke();
    if (opts.marker) {
      const [mx, my] = opts.marker, px = x0 + (mx + 1) / 2 * size, py = y0 + (1 - (my + 1) / 2) * size;
      ctx.strokeStyle = '#ff3030'; ctx.lineWidth = 2;
      ctx.beginPath(); ctx.moveTo(px - 6, py); ctx.lineTo(px + 6, py); ctx.moveTo(px, py - 6); ctx.lineTo(px, py + 6); ctx.stroke();
      ctx.lineWidth = 1;
    }
    const bx = x0 + size + 16, bh = size, by = y0;
    for (let k = 0; k < bh; k++) { const [R, G, B] = colour(1 - k / bh); ctx.fillStyle = `rgb(${R},${G},${B})`; ctx.fillRect(bx, by + k, 14, 1); }
    ctx.fillStyle = '#444'; ctx.textAlign = 'left';
    ctx.fillText(fmt(hi), bx + 18, by + 8); ctx.fillText(fmt(lo), bx + 18, by + bh);
    ctx.fillText(opts.label || '', bx + 18, by + bh / 2);
  }

  return { PALETTE, lineChart, polarChart, heatmap, fmt };
})();

'use strict';
// The review page's viewer: draws each case's golden and new render from their linear values
// (exposure and channel chosen in the bar), the difference of the chosen channel, and an
// inspector to swipe or flip between the two, zoom to single pixels and read the values under
// the cursor. Accept and reject post to the review server the page came from.
document.body.classList.add('js');
var cases = {};
var state = { channel: 'color', exposure: 0, mode: 'swipe' };

function goldrayCase(meta, b64) {
  var bin = atob(b64), bytes = new Uint8Array(bin.length);
  for (var i = 0; i < bin.length; i++) { bytes[i] = bin.charCodeAt(i); }
  var all = new Float32Array(bytes.buffer), n = meta.width * meta.height, planes = {};
  meta.planes.forEach(function (name, k) { planes[name] = all.subarray(k * n, (k + 1) * n); });
  var section = document.getElementById('case-' + meta.id);
  if (!section) { return; }
  var c = { meta: meta, planes: planes, section: section, n: n, flip: false, hover: null, view: null };
  c.depth = range(c, ['expected.Z', 'actual.Z'], function (v) { return v; });
  c.sigma = range(c, ['expected.var.R', 'expected.var.G', 'expected.var.B', 'actual.var.R', 'actual.var.G',
    'actual.var.B'], Math.sqrt);
  cases[meta.id] = c;
  setupInspector(c);
  c.hover = meta.worst;
  draw(c);
  readout(c);
}

// The smallest and largest finite value of the planes, through f.
function range(c, names, f) {
  var lo = Infinity, hi = -Infinity;
  names.forEach(function (name) {
    var p = c.planes[name];
    if (!p) { return; }
    for (var i = 0; i < p.length; i++) {
      var v = f(p[i]);
      if (isFinite(v)) { if (v < lo) { lo = v; } if (v > hi) { hi = v; } }
    }
  });
  return hi >= lo ? [lo, hi] : null;
}

function srgb(v) {
  v = v <= 0 ? 0 : v >= 1 ? 1 : v;
  return 255 * (v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055);
}

function canvasOf(img) {
  var canvas = document.createElement('canvas');
  canvas.width = img.width; canvas.height = img.height;
  canvas.getContext('2d').putImageData(img, 0, 0);
  return canvas;
}

// One side of a case in the chosen channel, as a canvas of the image's size; null when the side
// or the channel is absent.
function picture(c, side, channel) {
  var m = c.meta, gain = Math.pow(2, state.exposure), p = function (name) { return c.planes[side + '.' + name]; };
  if (channel === 'z') { channel = 'color'; }
  var img = new ImageData(m.width, m.height), d = img.data, i, k;
  if (channel === 'color' || channel === 'variance') {
    var prefix = channel === 'color' ? '' : 'var.', planes = [p(prefix + 'R'), p(prefix + 'G'), p(prefix + 'B')];
    if (!planes[0]) { return null; }
    var scale = channel === 'variance' ? (c.sigma && c.sigma[1] > 0 ? 1 / c.sigma[1] : 1) : 1;
    for (i = 0; i < c.n; i++) {
      for (k = 0; k < 3; k++) {
        var v = planes[k][i];
        if (channel === 'variance') { v = Math.sqrt(v) * scale; }
        d[4 * i + k] = m.linear || channel === 'variance' ? srgb(v * gain) : v * gain;
      }
      d[4 * i + 3] = 255;
    }
  } else if (channel === 'depth') {
    var z = p('Z');
    if (!z) { return null; }
    var lo = c.depth ? c.depth[0] : 0, span = c.depth && c.depth[1] > lo ? c.depth[1] - lo : 1;
    for (i = 0; i < c.n; i++) {
      var g = isFinite(z[i]) ? 30 + 225 * (z[i] - lo) / span : 0;
      d[4 * i] = d[4 * i + 1] = d[4 * i + 2] = g; d[4 * i + 3] = 255;
    }
  } else {
    var nx = p('N.X'), ny = p('N.Y'), nz = p('N.Z');
    if (!nx) { return null; }
    for (i = 0; i < c.n; i++) {
      d[4 * i] = 127.5 * (nx[i] + 1); d[4 * i + 1] = 127.5 * (ny[i] + 1); d[4 * i + 2] = 127.5 * (nz[i] + 1);
      d[4 * i + 3] = 255;
    }
  }
  return canvasOf(img);
}

// The dim grey of the golden that the suite's heatmap draws errors over.
function backdrop(c, i) {
  var r = c.planes['expected.R'], g = c.planes['expected.G'], b = c.planes['expected.B'];
  if (!r) { return 0; }
  var f = c.meta.linear ? srgb : function (v) { return v; };
  return (0.2126 * f(r[i]) + 0.7152 * f(g[i]) + 0.0722 * f(b[i])) * 0.3;
}

function mix(grey, hot, t) {
  var w = 0.4 + 0.6 * t;
  return [grey + (hot[0] - grey) * w, grey + (hot[1] - grey) * w, grey + (hot[2] - grey) * w];
}

// The difference of the chosen channel on the suite's scale (depth, normals), or the signed
// z of each pixel (z-evidence); null where the page shows the suite's own heatmap instead.
function difference(c, channel) {
  var m = c.meta, t = m.pixel, names = channel === 'depth' ? ['Z'] : channel === 'normal' ? ['N.X', 'N.Y', 'N.Z'] : null;
  if (channel === 'z') { names = ['z.R', 'z.G', 'z.B']; }
  if (!names || !(channel === 'z' ? c.planes['z.R'] : c.planes['expected.' + names[0]] && c.planes['actual.' + names[0]])) {
    return null;
  }
  var img = new ImageData(m.width, m.height), d = img.data;
  for (var i = 0; i < c.n; i++) {
    var grey = backdrop(c, i), rgb = [grey, grey, grey];
    if (channel === 'z') {
      var z = 0;
      names.forEach(function (name) { var v = c.planes[name][i]; if (Math.abs(v) > Math.abs(z)) { z = v; } });
      var s = (Math.abs(z) - 1) / (m.zCritical - 1);
      if (Math.abs(z) > m.zCritical) { rgb = [255, 0, 255]; }
      else if (s > 0) { rgb = mix(grey, z > 0 ? [255, 40 + 215 * s, 0] : [0, 90 + 165 * s, 255], s); }
    } else {
      var largest = 0, fails = false, broken = false;
      names.forEach(function (name) {
        var e = c.planes['expected.' + name][i], a = c.planes['actual.' + name][i];
        if (isNaN(e) !== isNaN(a)) { broken = true; return; }
        if (isFinite(e) !== isFinite(a)) { fails = true; return; }
        if (isFinite(e)) { var diff = Math.abs(a - e); largest = Math.max(largest, diff); fails = fails || diff > t; }
      });
      if (broken) { rgb = [0, 255, 255]; } else if (fails) { rgb = [255, 0, 255]; } else if (largest > 0) {
        var u = Math.min(1, Math.max(0, Math.log10(largest / t) / 3 + 1));
        rgb = mix(grey, [255, 40 + 215 * u, 0], u);
      }
    }
    d[4 * i] = rgb[0]; d[4 * i + 1] = rgb[1]; d[4 * i + 2] = rgb[2]; d[4 * i + 3] = 255;
  }
  return canvasOf(img);
}

function draw(c) {
  c.pictures = { expected: picture(c, 'expected', state.channel), actual: picture(c, 'actual', state.channel),
    diff: c.meta.pixel === null && state.channel !== 'z' ? null : difference(c, state.channel) };
  ['expected', 'actual', 'diff'].forEach(function (side) {
    var canvas = c.section.querySelector('canvas.pane[data-side="' + side + '"]'), src = c.pictures[side];
    var img = c.section.querySelector('figure.' + side + ' img');
    canvas.classList.toggle('hidden', !src);
    if (img) { img.classList.toggle('hidden', !!src); }
    if (src) {
      canvas.width = src.width; canvas.height = src.height;
      canvas.getContext('2d').drawImage(src, 0, 0);
    }
  });
  var heatmap = c.section.querySelector('figure.diff img');
  if (!c.pictures.diff && heatmap && heatmap.complete) { c.pictures.diff = heatmap; }
  drawView(c);
}

function setupInspector(c) {
  var canvas = c.section.querySelector('canvas.view'), swipe = c.section.querySelector('input.swipe');
  c.view = { canvas: canvas, swipe: swipe, zoom: c.section.querySelector('output.zoom'), scale: 0, ox: 0, oy: 0, drag: null };
  var at = function (e) {
    var r = canvas.getBoundingClientRect(), k = canvas.width / r.width;
    return [(e.clientX - r.left) * k, (e.clientY - r.top) * k];
  };
  canvas.addEventListener('wheel', function (e) {
    e.preventDefault();
    var v = c.view, p = at(e), f = e.deltaY < 0 ? 1.25 : 0.8, s = Math.min(256, Math.max(v.fit / 2, v.scale * f));
    v.ox = p[0] - (p[0] - v.ox) * s / v.scale; v.oy = p[1] - (p[1] - v.oy) * s / v.scale; v.scale = s;
    drawView(c);
  }, { passive: false });
  canvas.addEventListener('mousedown', function (e) { c.view.drag = [at(e), c.view.ox, c.view.oy, false]; });
  addEventListener('mouseup', function () {
    if (c.view.drag && !c.view.drag[3] && state.mode === 'flip') { c.flip = !c.flip; drawView(c); }
    c.view.drag = null;
  });
  canvas.addEventListener('mousemove', function (e) {
    var v = c.view, p = at(e);
    if (v.drag) {
      var dx = p[0] - v.drag[0][0], dy = p[1] - v.drag[0][1];
      if (Math.abs(dx) + Math.abs(dy) > 3) { v.drag[3] = true; }
      v.ox = v.drag[1] + dx; v.oy = v.drag[2] + dy;
    }
    c.hover = [Math.floor((p[0] - v.ox) / v.scale), Math.floor((p[1] - v.oy) / v.scale)];
    drawView(c); readout(c);
  });
  canvas.addEventListener('mouseleave', function () { c.hover = null; drawView(c); });
  canvas.addEventListener('dblclick', function () { c.view.scale = 0; drawView(c); });
  swipe.addEventListener('input', function () { drawView(c); });
}

function drawView(c) {
  var v = c.view, canvas = v.canvas, m = c.meta, ratio = window.devicePixelRatio || 1;
  var width = Math.round(canvas.parentNode.clientWidth * ratio) || m.width;
  var height = Math.round(width * m.height / m.width);
  if (canvas.width !== width || canvas.height !== height) { canvas.width = width; canvas.height = height; v.scale = 0; }
  v.fit = width / m.width;
  if (!v.scale) { v.scale = v.fit; v.ox = 0; v.oy = 0; }
  v.swipe.style.visibility = state.mode === 'swipe' && state.channel !== 'z' ? 'visible' : 'hidden';
  var ctx = canvas.getContext('2d'), p = c.pictures;
  ctx.imageSmoothingEnabled = false;
  ctx.fillStyle = '#111'; ctx.fillRect(0, 0, width, height);
  var put = function (src) {
    if (src) { ctx.drawImage(src, v.ox, v.oy, m.width * v.scale, m.height * v.scale); }
  };
  var shown = [];
  var label = function (text, x, align) {
    shown.push(text);
    ctx.font = (12 * ratio) + 'px system-ui,sans-serif'; ctx.textAlign = align;
    ctx.fillStyle = 'rgba(0,0,0,.6)';
    var w = ctx.measureText(text).width + 8 * ratio;
    ctx.fillRect(align === 'left' ? x : x - w, 0, w, 18 * ratio);
    ctx.fillStyle = '#fff'; ctx.fillText(text, align === 'left' ? x + 4 * ratio : x - 4 * ratio, 13 * ratio);
  };
  if (state.mode === 'diff' || state.channel === 'z') {
    put(p.diff); label(state.channel === 'z' ? 'z-evidence' : 'difference', 0, 'left');
  } else if (state.mode === 'flip') {
    put(c.flip ? p.actual : p.expected); label(c.flip ? 'new render (click or F: golden)' : 'golden (click or F: new render)', 0, 'left');
  } else {
    var split = Number(v.swipe.value) * width;
    put(p.expected);
    ctx.save(); ctx.beginPath(); ctx.rect(split, 0, width - split, height); ctx.clip(); put(p.actual); ctx.restore();
    ctx.fillStyle = '#ffeb3b'; ctx.fillRect(split - ratio, 0, 2 * ratio, height);
    label('golden', 0, 'left'); label('new render', width, 'right');
  }
  if (c.hover && v.scale >= 4) {
    ctx.strokeStyle = '#ffeb3b'; ctx.lineWidth = ratio;
    ctx.strokeRect(v.ox + c.hover[0] * v.scale, v.oy + c.hover[1] * v.scale, v.scale, v.scale);
  }
  // The labels drawn on the picture, for a screen reader; the zoom as screen pixels per image pixel.
  canvas.setAttribute('aria-label', shown.join(' | '));
  v.zoom.textContent = 'zoom ' + Number((v.scale / ratio).toPrecision(3)) + '×';
}

function fmt(v, linear) {
  if (v === undefined) { return ''; }
  if (isNaN(v)) { return 'NaN'; }
  if (!isFinite(v)) { return v > 0 ? 'inf' : '-inf'; }
  return linear ? Number(v.toPrecision(5)).toString() : v.toFixed(0);
}

function readout(c) {
  var table = c.section.querySelector('table.readout'), m = c.meta, h = c.hover;
  if (!h || h[0] < 0 || h[1] < 0 || h[0] >= m.width || h[1] >= m.height) { return; }
  var i = h[1] * m.width + h[0], columns = ['R', 'G', 'B', 'Z', 'N.X', 'N.Y', 'N.Z', 'var.R', 'var.G', 'var.B'];
  columns = columns.filter(function (n) { return c.planes['actual.' + n]; });
  var html = '<tr><th>(' + h[0] + ', ' + h[1] + ')</th>' + columns.map(function (n) { return '<th>' + n + '</th>'; }).join('') + '</tr>';
  var row = function (title, value, mark) {
    html += '<tr><th>' + title + '</th>' + columns.map(function (n) {
      var v = value(n);
      return '<td' + (mark && Math.abs(v) > m.pixel && n.indexOf('var.') !== 0 ? ' class="big"' : '') + '>' + fmt(v, m.linear) + '</td>';
    }).join('') + '</tr>';
  };
  var get = function (side, n) { var p = c.planes[side + '.' + n]; return p ? p[i] : undefined; };
  if (c.planes['expected.R']) { row('golden', function (n) { return get('expected', n); }); }
  row('new render', function (n) { return get('actual', n); });
  if (c.planes['expected.R']) {
    row('difference', function (n) { var e = get('expected', n), a = get('actual', n); return e === a ? 0 : a - e; }, true);
  }
  if (c.planes['z.R']) {
    html += '<tr><th>z</th>' + columns.map(function (n) {
      var p = c.planes['z.' + n]; return '<td>' + (p ? fmt(p[i], true) : '') + '</td>';
    }).join('') + '</tr>';
  }
  table.innerHTML = html;
}

function redrawAll() { Object.keys(cases).forEach(function (id) { draw(cases[id]); }); }

document.getElementById('channel').addEventListener('change', function (e) { state.channel = e.target.value; redrawAll(); });
document.getElementById('mode').addEventListener('change', function (e) {
  state.mode = e.target.value; Object.keys(cases).forEach(function (id) { drawView(cases[id]); });
});
document.getElementById('exposure').addEventListener('input', function (e) {
  state.exposure = Number(e.target.value);
  document.getElementById('exposure-value').textContent = (state.exposure >= 0 ? '+' : '') + state.exposure + ' EV';
  redrawAll();
});
addEventListener('keydown', function (e) {
  if (e.key !== 'f' && e.key !== 'F' || e.target.tagName === 'INPUT' && e.target.type !== 'range') { return; }
  state.mode = 'flip'; document.getElementById('mode').value = 'flip';
  Object.keys(cases).forEach(function (id) { cases[id].flip = !cases[id].flip; drawView(cases[id]); });
});
addEventListener('resize', function () { Object.keys(cases).forEach(function (id) { drawView(cases[id]); }); });

// Accept and reject: the server answers with what it wrote and removed, shown in the case's title.
function decided(result) {
  (result.decisions || []).forEach(function (d) {
    var section = document.getElementById('case-' + d.name);
    if (!section) { return; }
    section.classList.add('decided');
    section.querySelector('.status').textContent = d.accepted ? 'accepted: wrote ' + d.written.join(', ') : 'rejected: removed ' + d.removed.join(', ');
    section.querySelectorAll('button').forEach(function (b) { b.disabled = true; });
  });
  var open = document.querySelectorAll('section.case:not(.decided)').length, all = document.getElementById('accept-all');
  if (all) { all.disabled = open === 0; }
  document.body.setAttribute('data-open', open);
}
function post(path, section) {
  fetch(path, { method: 'POST' }).then(function (r) {
    return r.json().then(function (j) {
      if (!r.ok) { throw new Error(j.error || r.statusText); }
      decided(j);
    });
  }).catch(function (error) {
    var status = (section || document.body).querySelector('.status');
    if (status) { status.textContent = String(error.message || error); status.classList.add('error'); } else { alert(error); }
  });
}
document.querySelectorAll('button[data-action]').forEach(function (b) {
  b.addEventListener('click', function () {
    post('/' + b.getAttribute('data-action') + '/' + encodeURIComponent(b.getAttribute('data-case')), b.closest('section'));
  });
});
var acceptAll = document.getElementById('accept-all');
if (acceptAll) { acceptAll.addEventListener('click', function () { post('/accept-all', null); }); }

// What loaded, for the reviewer (a missing picture is outlined) and for a test in a headless browser.
addEventListener('load', function () {
  var loaded = 0, broken = 0, drawn = 0;
  document.querySelectorAll('img.picture').forEach(function (img) {
    if (img.complete && img.naturalWidth > 0) { loaded++; } else { broken++; img.style.outline = '3px solid #c62828'; }
  });
  document.querySelectorAll('canvas.pane').forEach(function (canvas) {
    if (!canvas.classList.contains('hidden') && canvas.width > 0) { drawn++; }
  });
  redrawAll();
  document.body.setAttribute('data-images-loaded', loaded);
  document.body.setAttribute('data-images-broken', broken);
  document.body.setAttribute('data-panes-drawn', drawn);
  document.body.setAttribute('data-cases-loaded', Object.keys(cases).length);
});

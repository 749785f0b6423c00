// The report's interaction: the panels of a feature pan and zoom together
// (wheel, drag, double-click to reset), the bars switch (on when the URL
// ends in #bars), and a click on a
// skeleton shows the node radius r and width 2r at its nearest vertex.
(function () {
  'use strict';
  var PICK_PX = 14;

  function parsePath(d) {
    var tokens = d.match(/[Mlz]|-?\d+/g) || [];
    var pts = [], x = 0, y = 0, mode = '', i = 0;
    while (i < tokens.length) {
      var t = tokens[i];
      if (t === 'M' || t === 'l' || t === 'z') { mode = t; i += 1; continue; }
      var a = parseInt(tokens[i], 10), b = parseInt(tokens[i + 1], 10);
      if (mode === 'M') { x = a; y = b; mode = 'l'; } else { x += a; y += b; }
      pts.push([x, y]);
      i += 2;
    }
    return pts;
  }

  function svgPoint(svg, e) {
    var m = svg.getScreenCTM();
    if (!m) { return null; }
    var p = new DOMPoint(e.clientX, e.clientY).matrixTransform(m.inverse());
    return [p.x, p.y];
  }

  function unitsPerPixel(svg) {
    var r = svg.getBoundingClientRect(), vb = svg.viewBox.baseVal;
    return Math.max(vb.width / Math.max(r.width, 1), vb.height / Math.max(r.height, 1));
  }

  function fmt(x) {
    if (!isFinite(x)) { return '–'; }
    var a = Math.abs(x);
    return a >= 100 ? x.toFixed(0) : a >= 1 ? x.toFixed(2) : x.toPrecision(3);
  }

  function nearest(path, p) {
    if (!path.pts) {
      path.pts = parsePath(path.getAttribute('d') || '');
      path.radii = (path.getAttribute('data-r') || '').split(' ').map(Number);
    }
    var best = -1, bestD = Infinity;
    for (var i = 0; i < path.pts.length; i += 1) {
      var dx = path.pts[i][0] - p[0], dy = path.pts[i][1] - p[1], d = dx * dx + dy * dy;
      if (d < bestD) { bestD = d; best = i; }
    }
    return { index: best, dist: Math.sqrt(bestD) };
  }

  function mark(svg, at, radius) {
    var g = svg.querySelector('g.pick');
    while (g.firstChild) { g.removeChild(g.firstChild); }
    var disc = document.createElementNS(svg.namespaceURI, 'circle');
    disc.setAttribute('class', 'disc');
    disc.setAttribute('cx', at[0]); disc.setAttribute('cy', at[1]); disc.setAttribute('r', radius);
    var node = document.createElementNS(svg.namespaceURI, 'circle');
    node.setAttribute('class', 'node');
    node.setAttribute('cx', at[0]); node.setAttribute('cy', at[1]);
    node.setAttribute('r', 3 * unitsPerPixel(svg));
    g.appendChild(disc); g.appendChild(node);
  }

  function pick(section, svg, e) {
    var path = svg.querySelector('path.skel');
    var p = svgPoint(svg, e);
    var info = section.querySelector('p.info');
    if (!path || !p) { return; }
    var hit = nearest(path, p);
    if (hit.index < 0 || hit.dist > PICK_PX * unitsPerPixel(svg)) { return; }
    var ds = section.dataset, scale = Number(ds.scale), units = ds.units ? ' ' + ds.units : '';
    var v = path.pts[hit.index], r = path.radii[hit.index];
    var x = Number(ds.x0) + v[0] / scale, y = Number(ds.y0) - v[1] / scale;
    var method = svg.closest('figure').dataset.method;
    section.querySelectorAll('g.pick').forEach(function (g) { while (g.firstChild) { g.removeChild(g.firstChild); } });
    if (isFinite(r)) { mark(svg, v, r * scale); }
    info.classList.add('picked');
    // The position to the frame's resolution (1 / scale); r is exact.
    var decimals = Math.max(0, Math.min(6, Math.ceil(Math.log10(scale))));
    info.textContent = method + ': node radius r = ' + fmt(r) + units + ', width 2r = ' + fmt(2 * r) + units +
      ' at x = ' + x.toFixed(decimals) + ', y = ' + y.toFixed(decimals);
  }

  function initSection(section) {
    var svgs = Array.prototype.slice.call(section.querySelectorAll('svg.map'));
    if (!svgs.length) { return; }
    var vb = svgs[0].viewBox.baseVal;
    var home = [vb.x, vb.y, vb.width, vb.height];
    var view = home.slice();
    function apply() {
      var text = view.map(function (v) { return v.toFixed(2); }).join(' ');
      svgs.forEach(function (s) { s.setAttribute('viewBox', text); });
    }
    svgs.forEach(function (svg) {
      var drag = null;
      svg.addEventListener('wheel', function (e) {
        e.preventDefault();
        var p = svgPoint(svg, e);
        if (!p) { return; }
        var k = Math.exp(e.deltaY * 0.0015);
        k = Math.min(Math.max(k, home[2] / 1000 / view[2]), home[2] * 1.5 / view[2]);
        view = [p[0] - (p[0] - view[0]) * k, p[1] - (p[1] - view[1]) * k, view[2] * k, view[3] * k];
        apply();
      }, { passive: false });
      svg.addEventListener('pointerdown', function (e) {
        drag = { x: e.clientX, y: e.clientY, view: view.slice(), upp: unitsPerPixel(svg), moved: false };
        svg.setPointerCapture(e.pointerId);
      });
      svg.addEventListener('pointermove', function (e) {
        if (!drag) { return; }
        var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
        if (Math.abs(dx) + Math.abs(dy) > 3) { drag.moved = true; svg.classList.add('dragging'); }
        if (drag.moved) {
          view = [drag.view[0] - dx * drag.upp, drag.view[1] - dy * drag.upp, drag.view[2], drag.view[3]];
          apply();
        }
      });
      svg.addEventListener('pointerup', function (e) {
        var wasDrag = drag && drag.moved;
        drag = null;
        svg.classList.remove('dragging');
        if (!wasDrag) { pick(section, svg, e); }
      });
      svg.addEventListener('dblclick', function () { view = home.slice(); apply(); });
    });
  }

  // The bars switch; `report.html#bars` opens the report with the bars shown.
  var toggle = document.getElementById('show-bars');
  if (toggle) {
    var sync = function () { document.body.classList.toggle('show-bars', toggle.checked); };
    toggle.addEventListener('change', sync);
    if (/^#bars\b/.test(location.hash)) { toggle.checked = true; }
    sync();
  }
  document.querySelectorAll('section.feature').forEach(initSection);
}());

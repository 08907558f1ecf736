// The run viewer: an orthographic orbit view of the chain, playback on the sample times,
// the energy ledger under a cursor. Plain JavaScript on two canvases; SCENE is the run
// (pendulum-cli/src/view/scene.rs). `#t=K` opens at sample K; `#selftest` checks the
// page in a headless browser and writes the result into <pre id="selftest">.
"use strict";
(function () {
  const S = SCENE;
  const n = S.links, count = S.times.length, per = 3 * (n + 1);
  const $ = (id) => document.getElementById(id);
  const canvas = $("chain"), ctx = canvas.getContext("2d");
  const slider = $("slider");
  const ROD = "#1f5fbf", MASS = [20, 50, 150], PIVOT = "#d62728";
  const view = { yaw: S.dim === 3 ? -0.5 : 0, pitch: S.dim === 3 ? 0.3 : 0, zoom: 1, frame: 0, playing: false,
    clock: 0, corotating: false, trail: true };

  // Point k (0: the pivot) of sample f, x, y, z with z up (a 2D run's plane x–y is shown
  // as x–z); co-rotating: turned back by the pivot's azimuth.
  function point(f, k) {
    const o = f * per + 3 * k;
    let x = S.unit * S.positions[o], y = S.unit * S.positions[o + 1], z = S.unit * S.positions[o + 2];
    if (S.dim === 2) return [x, 0, y];
    if (view.corotating && S.turning) {
      const a = -Math.atan2(S.positions[f * per + 1], S.positions[f * per]);
      [x, y] = [Math.cos(a) * x - Math.sin(a) * y, Math.sin(a) * x + Math.cos(a) * y];
    }
    return [x, y, z];
  }

  // The box the motion fills (every sample, every point): the view centres on it.
  const box = [0, 1, 2].map((a) => {
    let lo = Infinity, hi = -Infinity;
    for (let f = 0; f < count; f++) for (let k = 0; k <= n; k++) { const v = point(f, k)[a]; lo = Math.min(lo, v); hi = Math.max(hi, v); }
    return [lo, hi];
  });
  const centre = box.map(([lo, hi]) => (lo + hi) / 2);
  const extent = Math.max(...box.map(([lo, hi]) => hi - lo), 0.05 * S.reach);

  // Orthographic about the box's centre: turned by yaw about the vertical, tilted by
  // pitch; screen y up is z.
  function project(p) {
    const q = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
    const cy = Math.cos(view.yaw), sy = Math.sin(view.yaw), cp = Math.cos(view.pitch), sp = Math.sin(view.pitch);
    const across = cy * q[0] - sy * q[1], depth = sy * q[0] + cy * q[1];
    const up = cp * q[2] + sp * depth;
    const scale = view.zoom * 0.85 * Math.min(canvas.width, canvas.height) / extent;
    return [canvas.width / 2 + scale * across, canvas.height / 2 - scale * up, scale];
  }

  function line(a, b, colour, width, dash) {
    ctx.strokeStyle = colour; ctx.lineWidth = width; ctx.setLineDash(dash || []);
    ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke(); ctx.setLineDash([]);
  }

  function draw() {
    const f = view.frame;
    ctx.fillStyle = "#fff"; ctx.fillRect(0, 0, canvas.width, canvas.height);
    const scale = project([0, 0, 0])[2];
    // The rotation axis of a circling pivot: the vertical through the circle's centre.
    if (S.turning) line(project([0, 0, box[2][1] + 0.1 * extent]), project([0, 0, box[2][0] - 0.1 * extent]), "#888", 1, [6, 4]);
    // Scale bar: a round length near a quarter of the chain.
    const bar = Math.pow(10, Math.floor(Math.log10(extent / 4)));
    const length = [5, 2, 1].map((m) => m * bar).find((v) => v <= extent / 2) || bar;
    const x0 = 20, y0 = canvas.height - 20;
    line([x0, y0], [x0 + length * scale, y0], "#000", 2);
    ctx.fillStyle = "#000"; ctx.font = "13px system-ui, sans-serif";
    ctx.fillText(`${length} m`, x0, y0 - 6);
    // The tip's trail over the last 200 samples.
    if (view.trail) {
      ctx.strokeStyle = "rgba(214, 39, 40, 0.45)"; ctx.lineWidth = 1; ctx.beginPath();
      for (let g = Math.max(0, f - 200); g <= f; g++) {
        const q = project(point(g, n));
        if (g === Math.max(0, f - 200)) ctx.moveTo(q[0], q[1]); else ctx.lineTo(q[0], q[1]);
      }
      ctx.stroke();
    }
    const pts = [];
    for (let k = 0; k <= n; k++) pts.push(project(point(f, k)));
    for (let k = 1; k <= n; k++) line(pts[k - 1], pts[k], ROD, 2);
    const radius = Math.max(2, Math.min(6, 120 / n));
    ctx.fillStyle = `rgb(${MASS})`;
    for (let k = 1; k <= n; k++) { ctx.beginPath(); ctx.arc(pts[k][0], pts[k][1], radius, 0, 2 * Math.PI); ctx.fill(); }
    ctx.fillStyle = PIVOT; ctx.fillRect(pts[0][0] - 4, pts[0][1] - 4, 8, 8);
    ctx.fillStyle = "#000";
    ctx.fillText(`t = ${S.times[f].toFixed(3)} s${view.corotating && S.turning ? " (co-rotating)" : ""}`, 12, 20);
    $("time").textContent = `t = ${S.times[f].toFixed(3)} s (${f + 1}/${count})`;
    slider.value = String(f);
    drawEnergy();
  }

  const plot = $("energy"), pctx = plot.getContext("2d");
  const finite = (v) => Number.isFinite(v);
  const values = S.energy.concat(S.predicted).filter(finite);
  let low = Math.min(...values), high = Math.max(...values);
  if (!(high > low)) { low -= 1e-9 + Math.abs(low) * 1e-6; high += 1e-9 + Math.abs(high) * 1e-6; }
  const t0 = S.times[0], t1 = S.times[count - 1] > t0 ? S.times[count - 1] : t0 + 1;
  const px = (t) => 36 + (plot.width - 44) * (t - t0) / (t1 - t0);
  const py = (v) => plot.height - 18 - (plot.height - 28) * (v - low) / (high - low);
  function series(data, colour, dash) {
    pctx.strokeStyle = colour; pctx.lineWidth = 1.5; pctx.setLineDash(dash); pctx.beginPath();
    let started = false;
    for (let i = 0; i < count; i++) {
      if (!finite(data[i])) { started = false; continue; }
      if (started) pctx.lineTo(px(S.times[i]), py(data[i])); else pctx.moveTo(px(S.times[i]), py(data[i]));
      started = true;
    }
    pctx.stroke(); pctx.setLineDash([]);
  }
  function drawEnergy() {
    pctx.fillStyle = "#fff"; pctx.fillRect(0, 0, plot.width, plot.height);
    pctx.fillStyle = "#000"; pctx.font = "11px system-ui, sans-serif";
    pctx.fillText(high.toPrecision(5), 0, 12); pctx.fillText(low.toPrecision(5), 0, plot.height - 20);
    pctx.fillText(`${t0.toFixed(1)} s`, 36, plot.height - 4);
    pctx.fillText(`${t1.toFixed(1)} s`, plot.width - 48, plot.height - 4);
    series(S.energy, ROD, []);
    series(S.predicted, PIVOT, [4, 3]);
    const x = px(S.times[view.frame]);
    pctx.strokeStyle = "#000"; pctx.lineWidth = 1;
    pctx.beginPath(); pctx.moveTo(x, 0); pctx.lineTo(x, plot.height - 16); pctx.stroke();
  }

  function show(f) {
    view.frame = Math.max(0, Math.min(count - 1, f));
    view.clock = S.times[view.frame];
    draw();
  }
  function tick(last) {
    return (now) => {
      if (!view.playing) return;
      view.clock += (now - last) / 1000 * Number($("speed").value);
      let f = view.frame;
      while (f + 1 < count && S.times[f + 1] <= view.clock) f++;
      if (f === count - 1 && view.clock >= S.times[count - 1]) { view.playing = false; $("play").textContent = "▶"; }
      view.frame = f; draw();
      requestAnimationFrame(tick(now));
    };
  }
  function toggle() {
    view.playing = !view.playing;
    $("play").textContent = view.playing ? "❚❚" : "▶";
    if (view.playing) {
      if (view.frame === count - 1) show(0);
      requestAnimationFrame((now) => requestAnimationFrame(tick(now)));
    }
  }

  slider.max = String(count - 1);
  slider.addEventListener("input", () => show(Number(slider.value)));
  $("play").addEventListener("click", toggle);
  $("back").addEventListener("click", () => show(view.frame - 1));
  $("forward").addEventListener("click", () => show(view.frame + 1));
  $("corotating").addEventListener("change", (e) => { view.corotating = e.target.checked; draw(); });
  $("trail").addEventListener("change", (e) => { view.trail = e.target.checked; draw(); });
  if (!S.turning) $("corotating-label").hidden = true;
  document.addEventListener("keydown", (e) => {
    if (e.key === " ") { e.preventDefault(); toggle(); }
    if (e.key === "ArrowLeft") show(view.frame - 1);
    if (e.key === "ArrowRight") show(view.frame + 1);
  });
  let drag = null;
  canvas.addEventListener("mousedown", (e) => { drag = [e.clientX, e.clientY]; });
  window.addEventListener("mouseup", () => { drag = null; });
  window.addEventListener("mousemove", (e) => {
    if (!drag || S.dim === 2) return;
    view.yaw += 0.01 * (e.clientX - drag[0]);
    view.pitch = Math.max(-1.55, Math.min(1.55, view.pitch + 0.01 * (e.clientY - drag[1])));
    drag = [e.clientX, e.clientY]; draw();
  });
  canvas.addEventListener("wheel", (e) => { e.preventDefault(); view.zoom *= Math.exp(-0.001 * e.deltaY); draw(); });
  function fit() {
    canvas.width = canvas.clientWidth; canvas.height = canvas.clientHeight; draw();
  }
  window.addEventListener("resize", fit);

  $("parameters").textContent = S.parameters.join("\n") +
    `\n${count} frames shown of ${S.samples} samples (every ${S.every})`;
  const shape = S.shape;
  $("shape").textContent = shape
    ? `${shape.nodes} nodes (${shape.axis_crossings} axis crossings), tip radius ${Number(shape.tip_radius).toExponential(4)} m\n` +
      `${shape.settled ? "settled" : "not settled"} (drift ${Number(shape.drift).toExponential(1)} m)`
    : "(no shape.json: not a whirled 3D run)";

  // The masses' pixels of the shown sample must be drawn in the mass colour.
  function onChain(image, x, y) {
    for (let dy = -1; dy <= 1; dy++) for (let dx = -1; dx <= 1; dx++) {
      const i = 4 * (Math.round(y + dy) * canvas.width + Math.round(x + dx));
      if (Math.abs(image[i] - MASS[0]) < 40 && Math.abs(image[i + 1] - MASS[1]) < 40 && Math.abs(image[i + 2] - MASS[2]) < 40) return true;
    }
    return false;
  }
  function selftest() {
    const checks = [];
    for (const k of [0, Math.floor(count / 2), count - 1]) {
      slider.value = String(k);
      slider.dispatchEvent(new Event("input"));
      const image = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
      let masses = 0;
      for (let i = 1; i <= n; i++) { const [x, y] = project(point(view.frame, i)); if (onChain(image, x, y)) masses++; }
      let inked = 0;
      for (let i = 0; i < image.length; i += 4) if (image[i] + image[i + 1] + image[i + 2] < 600) inked++;
      checks.push({ asked: k, shown: view.frame, time: S.times[view.frame], label: $("time").textContent,
        masses_on_mass_pixels: masses, inked });
    }
    $("selftest").textContent = JSON.stringify({ frames: count, links: n, checks });
    $("selftest").hidden = false;
  }

  fit();
  const at = /^#t=(\d+)$/.exec(location.hash);
  show(at ? Number(at[1]) : 0);
  if (location.hash === "#selftest") selftest();
})();

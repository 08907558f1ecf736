// The run viewer: the chain under an orbit camera (draw.js), playback on the sample
// times, the energy ledger under a cursor. Plain JavaScript on two canvases; SCENE is the
// run (pendulum-experiment/src/page/scene.rs). `#t=K` opens at sample K; `#selftest` checks the
// page in a headless browser and writes the result into <pre id="selftest">.
"use strict";
(function () {
  const S = SCENE;
  const n = S.links, count = S.times.length, per = 3 * (n + 1);
  const $ = (id) => document.getElementById(id);
  const canvas = $("chain"), slider = $("slider");
  const view = { frame: 0, playing: false, clock: 0, corotating: false, trail: true };

  // Point k (0: the pivot) of sample f, x, y, z with z up (a 2D run's plane x–y is shown
  // as x–z); co-rotating: turned back by the pivot's azimuth φ, which the server sends
  // (S.phases, the core's TurningFrame).
  function point(f, k) {
    const o = f * per + 3 * k;
    let x = S.unit * S.positions[o], y = S.unit * S.positions[o + 1], z = S.unit * S.positions[o + 2];
    if (S.dim === 2) return [x, 0, y];
    if (view.corotating && S.turning) {
      const c = Math.cos(S.phases[f]), s = Math.sin(S.phases[f]);
      [x, y] = [c * x + s * y, -s * x + c * y];
    }
    return [x, y, z];
  }
  const points = (f) => Array.from({ length: n + 1 }, (_, k) => point(f, k));

  // The box the motion fills (every sample, every point): the view centres on it.
  const box = [0, 1, 2].map((a) => {
    let lo = Infinity, hi = -Infinity;
    for (let f = 0; f < count; f++) for (let k = 0; k <= n; k++) { const v = point(f, k)[a]; lo = Math.min(lo, v); hi = Math.max(hi, v); }
    return [lo, hi];
  });
  const extent = Math.max(...box.map(([lo, hi]) => hi - lo), 0.05 * S.reach);
  const camera = chainView(canvas, box.map(([lo, hi]) => (lo + hi) / 2), extent, S.dim === 3);

  function draw() {
    const f = view.frame;
    camera.clear();
    // The rotation axis of a circling pivot: the vertical through the circle's centre.
    if (S.turning) camera.axis(0, 0, box[2][1] + 0.1 * extent, box[2][0] - 0.1 * extent);
    camera.scaleBar();
    // The tip's trail over the last 200 samples.
    if (view.trail) {
      const tip = [];
      for (let g = Math.max(0, f - 200); g <= f; g++) tip.push(point(g, n));
      camera.trail(tip);
    }
    camera.chain(points(f));
    camera.label(`t = ${S.times[f].toFixed(3)} s${view.corotating && S.turning ? " (co-rotating)" : ""}`);
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
  // The plot right of its value labels (LEFT px), above its time labels.
  const LEFT = 70;
  const px = (t) => LEFT + (plot.width - LEFT - 8) * (t - t0) / (t1 - t0);
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
    pctx.textAlign = "right";
    pctx.fillText(`${high.toPrecision(5)} J`, LEFT - 6, py(high) + 4);
    pctx.fillText(`${low.toPrecision(5)} J`, LEFT - 6, py(low) + 4);
    pctx.fillText(`${t1.toFixed(1)} s`, plot.width - 4, plot.height - 3);
    pctx.textAlign = "left";
    pctx.fillText(`${t0.toFixed(1)} s`, LEFT, plot.height - 3);
    pctx.strokeStyle = "#999"; pctx.lineWidth = 1;
    pctx.beginPath(); pctx.moveTo(LEFT - 2, 4); pctx.lineTo(LEFT - 2, plot.height - 15);
    pctx.lineTo(plot.width - 4, plot.height - 15); pctx.stroke();
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
  camera.orbit(draw);

  $("parameters").textContent = S.parameters.join("\n") +
    `\n${count} frames shown of ${S.samples} samples (every ${S.every})`;
  const shape = S.shape;
  // Numbers never wrap inside (a non-breaking hyphen in exponents); counts agree with their nouns.
  const number = (x, digits) => Number(x).toPrecision(digits).replace("-", "\u2011");
  const count_of = (k, noun) => `${k} ${noun}${k === 1 ? "" : "s"}`;
  $("shape").textContent = shape
    ? `${count_of(shape.nodes, "node")} (${count_of(shape.axis_crossings, "axis crossing")}; the pivot counts)\n` +
      `tip radius ${number(shape.tip_radius, 4)} m\n` +
      `${shape.settled ? "settled" : "not settled"} (drift ${number(shape.drift, 2)} m)`
    : "(no shape.json: not a whirled 3D run)";

  // For each of three samples: the slider moved there, what is shown and whether the
  // masses of that sample are drawn where their positions say; the middle one's picture.
  function selftest() {
    const checks = [], middle = Math.floor(count / 2);
    let picture = null;
    for (const k of [0, middle, count - 1]) {
      slider.value = String(k);
      slider.dispatchEvent(new Event("input"));
      const seen = camera.inspect(points(view.frame).slice(1));
      checks.push({ asked: k, shown: view.frame, time: S.times[view.frame], label: $("time").textContent, ...seen });
      if (k === middle) picture = { sample: view.frame, ...camera.picture() };
    }
    $("selftest").textContent = JSON.stringify({ frames: count, links: n, checks, picture });
    $("selftest").hidden = false;
  }

  // A whirl opens at its end, where its answer (the shape it settled in) is; other runs at
  // the start. `#t=K` opens at sample K.
  const at = /^#t=(\d+)$/.exec(location.hash);
  show(at ? Number(at[1]) : shape ? count - 1 : 0);
  if (location.hash === "#selftest") selftest();
})();

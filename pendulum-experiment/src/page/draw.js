// Drawing a chain on a canvas, shared by the run viewer (viewer.js) and the live page
// (live.js): an orthographic orbit view about a box's centre, the chain, the pivot, the
// tip's trail, the rotation axis, a scale bar, and the pixel test of the self-tests.
"use strict";
const ROD = "#1f5fbf", MASS = [20, 50, 150], PIVOT = "#d62728";

// A view of `canvas` centred on `centre` (m, z up) fitting `extent` (m) at zoom 1,
// turned by yaw about the vertical and tilted by pitch (3D; a plane's yaw = pitch = 0).
function chainView(canvas, centre, extent, spatial) {
  const ctx = canvas.getContext("2d");
  const v = { ctx, yaw: spatial ? -0.5 : 0, pitch: spatial ? 0.3 : 0, zoom: 1, centre, extent };

  // Screen position [x, y] and pixels per metre of the point p = [x, y, z].
  v.project = (p) => {
    const q = [p[0] - v.centre[0], p[1] - v.centre[1], p[2] - v.centre[2]];
    const cy = Math.cos(v.yaw), sy = Math.sin(v.yaw), cp = Math.cos(v.pitch), sp = Math.sin(v.pitch);
    const across = cy * q[0] - sy * q[1], depth = sy * q[0] + cy * q[1];
    const up = cp * q[2] + sp * depth;
    const scale = v.zoom * 0.85 * Math.min(canvas.width, canvas.height) / v.extent;
    return [canvas.width / 2 + scale * across, canvas.height / 2 - scale * up, scale];
  };
  // The displacement in space, parallel to the screen, that moves a point by (dx, dy)
  // pixels (the screen's right is (cos yaw, −sin yaw, 0), its up
  // (sin pitch sin yaw, sin pitch cos yaw, cos pitch)).
  v.unproject = (dx, dy) => {
    const s = v.project([0, 0, 0])[2];
    const cy = Math.cos(v.yaw), sy = Math.sin(v.yaw), cp = Math.cos(v.pitch), sp = Math.sin(v.pitch);
    const right = dx / s, up = -dy / s;
    return [cy * right + sp * sy * up, -sy * right + sp * cy * up, cp * up];
  };

  function line(a, b, colour, width, dash) {
    ctx.strokeStyle = colour; ctx.lineWidth = width; ctx.setLineDash(dash || []);
    ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke(); ctx.setLineDash([]);
  }
  v.clear = () => { ctx.fillStyle = "#fff"; ctx.fillRect(0, 0, canvas.width, canvas.height); };
  // The vertical through (x, y) from z = top to z = bottom, dashed: a rotation axis.
  v.axis = (x, y, top, bottom) => line(v.project([x, y, top]), v.project([x, y, bottom]), "#888", 1, [6, 4]);
  // A round length near a quarter of the extent, in the lower left corner.
  v.scaleBar = () => {
    const scale = v.project([0, 0, 0])[2];
    const bar = Math.pow(10, Math.floor(Math.log10(v.extent / 4)));
    const length = [5, 2, 1].map((m) => m * bar).find((u) => u <= v.extent / 2) || bar;
    const x0 = 20, y0 = canvas.height - 20;
    line([x0, y0], [x0 + length * scale, y0], "#000", 2);
    ctx.fillStyle = "#000"; ctx.font = "13px system-ui, sans-serif";
    ctx.fillText(`${length} m`, x0, y0 - 6);
  };
  // A polyline through the points (the tip's trail).
  v.trail = (points) => {
    ctx.strokeStyle = "rgba(214, 39, 40, 0.45)"; ctx.lineWidth = 1; ctx.beginPath();
    points.forEach((p, i) => { const q = v.project(p); if (i === 0) ctx.moveTo(q[0], q[1]); else ctx.lineTo(q[0], q[1]); });
    ctx.stroke();
  };
  // The chain: points[0] the pivot, then every mass.
  v.chain = (points) => {
    const n = points.length - 1, pts = points.map(v.project);
    for (let k = 1; k <= n; k++) line(pts[k - 1], pts[k], ROD, 2);
    const radius = Math.max(2, Math.min(6, 120 / n));
    ctx.fillStyle = `rgb(${MASS})`;
    for (let k = 1; k <= n; k++) { ctx.beginPath(); ctx.arc(pts[k][0], pts[k][1], radius, 0, 2 * Math.PI); ctx.fill(); }
    ctx.fillStyle = PIVOT; ctx.fillRect(pts[0][0] - 4, pts[0][1] - 4, 8, 8);
  };
  v.label = (text) => { ctx.fillStyle = "#000"; ctx.font = "13px system-ui, sans-serif"; ctx.fillText(text, 12, 20); };

  // Drag to turn (3D), wheel to zoom; `grab(x, y)` may claim a drag first (it returns a
  // function of the pointer's move in pixels, or nothing).
  v.orbit = (redraw, grab) => {
    let drag = null, held = null;
    canvas.addEventListener("mousedown", (e) => {
      const r = canvas.getBoundingClientRect();
      held = grab ? grab(e.clientX - r.left, e.clientY - r.top) : null;
      drag = [e.clientX, e.clientY];
    });
    window.addEventListener("mouseup", () => { drag = null; held = null; });
    window.addEventListener("mousemove", (e) => {
      if (!drag) return;
      const dx = e.clientX - drag[0], dy = e.clientY - drag[1];
      if (held) { held(dx, dy); return; }
      if (!spatial) return;
      v.yaw += 0.01 * dx;
      v.pitch = Math.max(-1.55, Math.min(1.55, v.pitch + 0.01 * dy));
      drag = [e.clientX, e.clientY]; redraw();
    });
    canvas.addEventListener("wheel", (e) => { e.preventDefault(); v.zoom *= Math.exp(-0.001 * e.deltaY); redraw(); });
    const fit = () => { canvas.width = canvas.clientWidth; canvas.height = canvas.clientHeight; redraw(); };
    window.addEventListener("resize", fit);
    fit();
  };

  // What the self-tests report of the view: the camera and the canvas as drawn (a PNG
  // data URL), for a test to project the positions on its own and look at the pixels.
  v.picture = () => ({ centre: v.centre, yaw: v.yaw, pitch: v.pitch, scale: v.project(v.centre)[2],
    width: canvas.width, height: canvas.height, image: canvas.toDataURL("image/png") });

  // How many of the points are drawn in the mass colour (within a pixel), and how many
  // pixels are inked at all: the self-tests' reading of the canvas.
  v.inspect = (points) => {
    const image = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
    const onMass = ([x, y]) => {
      for (let dy = -1; dy <= 1; dy++) for (let dx = -1; dx <= 1; dx++) {
        const i = 4 * (Math.round(y + dy) * canvas.width + Math.round(x + dx));
        if ([0, 1, 2].every((c) => Math.abs(image[i + c] - MASS[c]) < 40)) return true;
      }
      return false;
    };
    let inked = 0;
    for (let i = 0; i < image.length; i += 4) if (image[i] + image[i + 1] + image[i + 2] < 600) inked++;
    return { masses_on_mass_pixels: points.filter((p) => onMass(v.project(p))).length, inked };
  };
  return v;
}

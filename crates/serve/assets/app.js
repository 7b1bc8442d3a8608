// The shop-floor page of `chatter serve`: five screens over the JSON API, charts drawn as SVG
// here (no library, nothing loaded from the network). Text from the server or the user is only
// ever set as textContent.
"use strict";

const state = { setup: null, detail: null, job: null, poll: null, proposed: null };

function el(tag, attrs, ...children) {
  const svg = ["svg", "path", "line", "circle", "text", "g", "rect", "polyline", "polygon"].includes(tag);
  const e = svg ? document.createElementNS("http://www.w3.org/2000/svg", tag) : document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (v !== null && v !== undefined) e.setAttribute(k, v);
  }
  for (const c of children.flat()) {
    if (c === null || c === undefined) continue;
    e.append(c instanceof Node ? c : document.createTextNode(String(c)));
  }
  return e;
}

function show(text, kind) {
  const m = document.getElementById("message");
  m.textContent = text;
  m.className = kind || "error";
  m.hidden = !text;
}

async function api(path, options) {
  let response;
  try {
    response = await fetch(path, options);
  } catch (e) {
    throw new Error("the server did not answer: " + e.message);
  }
  let body = null;
  try {
    body = await response.json();
  } catch (e) {
    body = null;
  }
  if (!response.ok) {
    if (response.status === 413) throw new Error("file: the upload is larger than the server's limit (8 MiB)");
    throw new Error((body && body.error) || ("the server answered " + response.status));
  }
  return body;
}

function postJson(path, value) {
  return api(path, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(value) });
}

function fmt(v, digits) {
  if (v === null || v === undefined || Number.isNaN(v)) return "—";
  return Number(v).toFixed(digits === undefined ? 1 : digits);
}

// ---- charts ----------------------------------------------------------------------------
// chart(container, {xlabel, ylabel, logy, series: [{points: [[x, y]], color, dash, kind, label}],
//                   hover(x) -> text, click(x, y)})
function chart(container, spec) {
  const W = 900, H = 420, L = 70, R = 20, T = 20, B = 50;
  const all = spec.series.flatMap(s => s.points).filter(p => p && Number.isFinite(p[0]) && Number.isFinite(p[1]));
  const ty = v => spec.logy ? Math.log10(Math.max(v, 1e-300)) : v;
  let xs = all.map(p => p[0]), ys = all.map(p => ty(p[1]));
  let x0 = spec.xmin !== undefined ? spec.xmin : Math.min(...xs), x1 = Math.max(...xs);
  let y0 = spec.logy ? Math.min(...ys) : Math.min(0, ...ys), y1 = Math.max(...ys);
  if (spec.ymax !== undefined) y1 = Math.min(y1, spec.ymax);
  if (!(x1 > x0)) { x1 = x0 + 1; }
  if (!(y1 > y0)) { y1 = y0 + 1; }
  y1 += 0.05 * (y1 - y0);
  const px = x => L + (x - x0) / (x1 - x0) * (W - L - R);
  const py = y => T + (1 - (ty(y) - y0) / (y1 - y0)) * (H - T - B);
  const ix = p => x0 + (p - L) / (W - L - R) * (x1 - x0);
  const iy = p => { const v = y0 + (1 - (p - T) / (H - T - B)) * (y1 - y0); return spec.logy ? Math.pow(10, v) : v; };
  const svg = el("svg", { width: W, height: H, viewBox: `0 0 ${W} ${H}`, role: "img" });
  const g = el("g", {});
  for (let k = 0; k <= 5; k++) {
    const xv = x0 + k / 5 * (x1 - x0), yv = y0 + k / 5 * (y1 - y0);
    g.append(el("line", { x1: px(xv), x2: px(xv), y1: T, y2: H - B, stroke: "#eee" }));
    g.append(el("text", { x: px(xv), y: H - B + 16, "text-anchor": "middle", "font-size": 12 }, fmt(xv, xv >= 100 ? 0 : 1)));
    const yp = T + (1 - k / 5) * (H - T - B);
    g.append(el("line", { x1: L, x2: W - R, y1: yp, y2: yp, stroke: "#eee" }));
    g.append(el("text", { x: L - 6, y: yp + 4, "text-anchor": "end", "font-size": 12 }, spec.logy ? Math.pow(10, yv).toPrecision(2) : fmt(yv, 1)));
  }
  g.append(el("text", { x: (L + W - R) / 2, y: H - 10, "text-anchor": "middle", "font-size": 13 }, spec.xlabel));
  g.append(el("text", { x: 14, y: (T + H - B) / 2, "text-anchor": "middle", "font-size": 13, transform: `rotate(-90 14 ${(T + H - B) / 2})` }, spec.ylabel));
  g.append(el("rect", { x: L, y: T, width: W - L - R, height: H - T - B, fill: "none", stroke: "#999" }));
  svg.append(g);
  const clip = v => Math.max(T, Math.min(H - B, v));
  let legendY = T + 14;
  for (const s of spec.series) {
    const pts = s.points.filter(p => p && Number.isFinite(p[0]) && Number.isFinite(p[1]));
    const kind = s.kind || "line";
    if (kind === "line") {
      // a gap in the data (null depth: no limit) breaks the line
      let d = "", pen = false;
      for (const p of s.points) {
        if (!p || !Number.isFinite(p[1])) { pen = false; continue; }
        d += (pen ? "L" : "M") + px(p[0]).toFixed(1) + " " + clip(py(p[1])).toFixed(1);
        pen = true;
      }
      svg.append(el("path", { d, fill: "none", stroke: s.color, "stroke-width": s.width || 2, "stroke-dasharray": s.dash || null, class: s.cls || null }));
    } else {
      for (const p of pts) {
        const x = px(p[0]), y = clip(py(p[1]));
        let mark;
        if (kind === "o") mark = el("circle", { cx: x, cy: y, r: s.r || 5, fill: "none", stroke: s.color, "stroke-width": 2 });
        else if (kind === "dot") mark = el("circle", { cx: x, cy: y, r: s.r || 2.5, fill: s.color });
        else if (kind === "x") mark = el("path", { d: `M${x - 5} ${y - 5}L${x + 5} ${y + 5}M${x - 5} ${y + 5}L${x + 5} ${y - 5}`, stroke: s.color, "stroke-width": 2.5 });
        else if (kind === "star") mark = el("polygon", { points: star(x, y), fill: s.color, stroke: "#000", class: s.cls || null });
        else if (kind === "vline") mark = el("line", { x1: x, x2: x, y1: T, y2: H - B, stroke: s.color, "stroke-dasharray": s.dash || null });
        if (p[2]) mark.append(el("title", {}, p[2]));
        svg.append(mark);
      }
    }
    if (s.label) {
      const lx = spec.legendLeft ? L + 10 : W - R - 230;
      svg.append(el("line", { x1: lx, x2: lx + 25, y1: legendY - 4, y2: legendY - 4, stroke: s.color, "stroke-width": 3, "stroke-dasharray": s.dash || null }));
      svg.append(el("text", { x: lx + 30, y: legendY, "font-size": 12 }, s.label));
      legendY += 16;
    }
  }
  const guide = el("line", { x1: 0, x2: 0, y1: T, y2: H - B, stroke: "#555", "stroke-dasharray": "3 3", visibility: "hidden" });
  svg.append(guide);
  const tip = document.getElementById("tooltip");
  const at = ev => { const r = svg.getBoundingClientRect(); return [ev.clientX - r.left, ev.clientY - r.top]; };
  if (spec.hover) {
    svg.addEventListener("mousemove", ev => {
      const [mx, my] = at(ev);
      if (mx < L || mx > W - R || my < T || my > H - B) { guide.setAttribute("visibility", "hidden"); tip.hidden = true; return; }
      guide.setAttribute("x1", mx); guide.setAttribute("x2", mx); guide.setAttribute("visibility", "visible");
      tip.textContent = spec.hover(ix(mx), iy(my));
      tip.style.left = (ev.clientX + 14) + "px"; tip.style.top = (ev.clientY + 14) + "px"; tip.hidden = false;
    });
    svg.addEventListener("mouseleave", () => { guide.setAttribute("visibility", "hidden"); tip.hidden = true; });
  }
  if (spec.click) {
    svg.addEventListener("click", ev => {
      const [mx, my] = at(ev);
      if (mx >= L && mx <= W - R && my >= T && my <= H - B) spec.click(ix(mx), iy(my));
    });
  }
  container.replaceChildren(svg);
  return svg;
}

function star(x, y) {
  const p = [];
  for (let k = 0; k < 10; k++) {
    const r = k % 2 ? 5 : 12, a = Math.PI / 5 * k - Math.PI / 2;
    p.push((x + r * Math.cos(a)).toFixed(1) + "," + (y + r * Math.sin(a)).toFixed(1));
  }
  return p.join(" ");
}

// ---- setups ----------------------------------------------------------------------------
async function loadSetups(select) {
  const { setups } = await api("/api/setups");
  const s = document.getElementById("setup-select");
  s.replaceChildren(...setups.map(x => el("option", { value: x.id }, x.name)));
  if (!setups.length) {
    s.append(el("option", { value: "" }, "no setup yet: create one"));
    document.getElementById("new-setup-box").open = true;
    state.setup = null;
    return;
  }
  state.setup = select || (setups.some(x => x.id === state.setup) ? state.setup : setups[0].id);
  s.value = state.setup;
  await loadDetail();
}

async function loadDetail() {
  if (!state.setup) return;
  const d = await api(`/api/setups/${state.setup}`);
  state.detail = d;
  const st = d.setup;
  document.getElementById("setup-summary").textContent =
    `${st.machine || "machine ?"} · ${st.tool || "tool ?"} · ${st.holder || "holder ?"} · ${d.cuts.length} cuts · ${d.poles} poles`;
  renderModel(d);
  renderCuts(d);
  renderJobs(d);
  renderExport(d);
}

function renderModel(d) {
  const box = document.getElementById("model-summary");
  if (!d.model) {
    box.replaceChildren(el("p", {}, "No model yet: upload a tap test or a model file."));
    document.getElementById("fit-result").replaceChildren();
    return;
  }
  const m = d.model.model;
  const op = m.operation || {};
  box.replaceChildren(
    el("h3", {}, "Current model"),
    el("p", {}, `${d.model.source} (version ${d.model_versions}, ${d.model.created_at} UTC) — ${op.kind}, ${op.teeth || "?"} teeth, radial immersion ${op.radial_immersion}, ${op.direction || ""} milling`),
    el("table", { id: "mode-table" },
      el("tr", {}, el("th", {}, "direction"), el("th", {}, "f (Hz)"), el("th", {}, "ζ (%)"), el("th", {}, "k (N/µm)")),
      (m.modes || []).map(x => el("tr", {}, el("td", { class: "text" }, x.direction || "shape"), el("td", {}, fmt(x.frequency_hz, 1)),
        el("td", {}, fmt(100 * x.damping_ratio, 2)), el("td", {}, fmt((x.stiffness_n_per_m || NaN) / 1e6, 2))))));
  renderFit(d.model.fit);
}

function renderFit(fit) {
  const box = document.getElementById("fit-result");
  if (!fit) { box.replaceChildren(); return; }
  const overlay = el("div", { class: "chart", id: "overlay-chart" });
  const stab = el("div", { class: "chart", id: "stabilization-chart" });
  box.replaceChildren(
    el("h3", {}, `Fit of ${fit.file}: ${fit.modes.length} mode(s), ${fit.band_hz[0].toFixed(0)}–${fit.band_hz[1].toFixed(0)} Hz, direction ${fit.directions.join(" and ")}`),
    el("table", { id: "fit-table" },
      el("tr", {}, el("th", {}, "f (Hz)"), el("th", {}, "ζ (%)"), el("th", {}, "k (N/µm)"), el("th", {}, "stable in orders")),
      fit.modes.map(x => el("tr", {}, el("td", {}, fmt(x.frequency_hz, 1)), el("td", {}, fmt(100 * x.damping_ratio, 2)),
        el("td", {}, fmt((x.stiffness_n_per_m || NaN) / 1e6, 2)), el("td", {}, fmt(100 * x.stability_share, 0) + " %")))),
    el("p", {}, `Misfit (NRMSE): real modes of the model ${fmt(100 * fit.nrmse_real_modes, 1)} %, complex modes with residual terms ${fmt(100 * fit.nrmse_complex_modes_with_residuals, 1)} %.`),
    overlay, stab);
  chart(overlay, {
    xlabel: "frequency (Hz)", ylabel: "|H| (µm/N)", logy: true,
    series: [
      { points: fit.overlay_um_per_n.map(p => [p[0], p[1]]), color: "#15c", label: "measured |H|" },
      { points: fit.overlay_um_per_n.map(p => [p[0], p[2]]), color: "#d22", dash: "6 4", label: "fitted modes" },
    ],
    hover: x => { const p = nearest(fit.overlay_um_per_n, x); return `${fmt(p[0], 1)} Hz\nmeasured ${p[1].toPrecision(3)} µm/N\nfitted ${p[2].toPrecision(3)} µm/N`; },
  });
  chart(stab, {
    xlabel: "frequency (Hz)", ylabel: "model order", xmin: fit.band_hz[0],
    series: [
      { points: fit.stabilization.filter(p => !p[2]).map(p => [p[1], p[0]]), color: "#bbb", kind: "dot", label: "pole" },
      { points: fit.stabilization.filter(p => p[2]).map(p => [p[1], p[0]]), color: "#d22", kind: "dot", label: "stable pole" },
      { points: fit.modes.map(m => [m.frequency_hz, 0]), color: "#15c", kind: "vline", dash: "4 3", label: "chosen mode" },
    ],
  });
}

function nearest(points, x) {
  let best = points[0];
  for (const p of points) if (Math.abs(p[0] - x) < Math.abs(best[0] - x)) best = p;
  return best;
}

// ---- lobes -----------------------------------------------------------------------------
async function showLobes() {
  if (!state.setup) throw new Error("create or choose a setup first");
  const f = new FormData(document.getElementById("lobes-form"));
  const started = performance.now();
  const box = document.getElementById("lobes-chart");
  box.replaceChildren(el("p", {}, "computing the lobes…"));
  const q = new URLSearchParams({ max_depth_mm: f.get("max_depth_mm"), risk: f.get("risk") });
  const r = await api(`/api/setups/${state.setup}/lobes?${q}`);
  drawLobes(r);
  // on screen: after the next frame is laid out and painted
  await new Promise(done => requestAnimationFrame(() => setTimeout(done, 0)));
  const ms = performance.now() - started;
  const t = document.getElementById("lobes-time");
  t.textContent = `on screen in ${ms.toFixed(0)} ms (server ${r.server_ms.toFixed(0)} ms)`;
  t.dataset.ms = ms.toFixed(1);
}

function drawLobes(r) {
  const d = r.diagram;
  const lobes = d.lobes.map(p => [p[0], p[1], p[2]]);
  const finiteDepths = lobes.map(p => p[1]).filter(Number.isFinite);
  const top = Math.max(...finiteDepths, ...r.cuts.map(c => c.depth_mm)) * 1.15;
  const rec = d.recommended;
  const series = [
    { points: d.upper, color: "#7a7", dash: "5 4", width: 1.5, label: "upper Type B offset (001)" },
    { points: d.lower, color: "#a77", dash: "5 4", width: 1.5, label: "lower Type B offset (001)" },
    { points: lobes.map(p => [p[0], p[1] === null ? NaN : p[1]]), color: "#15c", label: "limiting depth (FDM)", cls: "lobe-line" },
    { points: r.cuts.filter(c => c.stable).map(c => [c.speed_rpm, c.depth_mm, `cut ${c.id}: stable`]), color: "#070", kind: "o", label: "stable cut" },
    { points: r.cuts.filter(c => !c.stable).map(c => [c.speed_rpm, c.depth_mm, `cut ${c.id}: chatter`]), color: "#c00", kind: "x", label: "chatter cut" },
  ];
  if (rec) series.push({ points: [[rec.speed_rpm, rec.depth_mm, "recommended cut"]], color: "#f90", kind: "star", label: "recommended cut", cls: "recommended" });
  chart(document.getElementById("lobes-chart"), {
    xlabel: "spindle speed (rpm)", ylabel: "axial depth (mm)", ymax: top, series, legendLeft: true,
    hover: (x, y) => {
      const p = nearest(lobes, x);
      const limit = p[1] === null ? "no limit below the ceiling" : `${fmt(p[1], 2)} mm`;
      return `${fmt(p[0], 0)} rpm\nlimiting depth ${limit}\nchatter at ${p[2] === null ? "—" : fmt(p[2], 0) + " Hz"}\ncursor depth ${fmt(y, 2)} mm\nclick to propose this cut`;
    },
    click: (x, y) => proposeCut(x, y, nearest(lobes, x)),
  });
  const box = document.getElementById("recommendation");
  if (!rec) { box.replaceChildren(el("p", {}, "No recommendation: turning models have lobes only.")); return; }
  box.replaceChildren(
    el("p", { class: "recommend", id: "recommended-cut" },
      `Recommended cut: ${fmt(rec.speed_rpm, 0)} rpm at ${fmt(rec.depth_mm, 2)} mm ` +
      `(limit there ${fmt(rec.limiting_depth_mm, 2)} mm, derated ${fmt(rec.derated_depth_mm, 2)} mm for a risk of ${d.risk}; ` +
      `limited by ${rec.limited_by.replace("_", " ")}${rec.mrr_cm3_per_min ? `; MRR ${fmt(rec.mrr_cm3_per_min, 0)} cm³/min` : ""}).`),
    el("ul", {}, rec.reasons.map(t => el("li", {}, t))),
    el("button", { type: "button", id: "use-recommended" }, "Log this cut"));
  document.getElementById("use-recommended").onclick = () => proposeCut(rec.speed_rpm, rec.depth_mm, null);
}

function proposeCut(speed, depth, point) {
  const f = document.getElementById("cut-form");
  f.elements.speed_rpm.value = speed.toFixed(0);
  f.elements.depth_mm.value = depth.toFixed(2);
  if (document.getElementById("recording-form")) {
    const g = document.getElementById("recording-form");
    g.elements.speed_rpm.value = speed.toFixed(0);
    g.elements.depth_mm.value = depth.toFixed(2);
  }
  const risk = point && point[1] !== null ? (depth < point[1] ? "below the limit: predicted stable" : "above the limit: predicted chatter") : "";
  show(`Proposed cut ${speed.toFixed(0)} rpm, ${depth.toFixed(2)} mm ${risk} — filled in on the Cut log screen.`, "ok");
}

// ---- cut log ---------------------------------------------------------------------------
function renderCuts(d) {
  const t = document.getElementById("cut-table");
  t.replaceChildren(
    el("tr", {}, ["#", "speed (rpm)", "depth (mm)", "result", "chatter (Hz)", "from", "recording", ""].map(h => el("th", {}, h))),
    ...d.cuts.map((c, k) => {
      const flip = el("button", { type: "button", class: "overrule" }, c.stable ? "mark chatter" : "mark stable");
      flip.onclick = () => run(async () => {
        await postJson(`/api/cuts/${c.id}/result`, { stable: !c.stable });
        await loadDetail();
        show(`cut ${k + 1} ${c.stable ? "marked chatter" : "marked stable"}${c.origin === "detected" ? " (detection overruled)" : ""}`, "ok");
      });
      return el("tr", {},
        el("td", {}, k + 1), el("td", {}, fmt(c.speed_rpm, 0)), el("td", {}, fmt(c.depth_mm, 2)),
        el("td", { class: c.stable ? "verdict-stable" : "verdict-chatter" }, (c.stable ? "stable" : "chatter") + (c.overruled ? " (overruled)" : "")),
        el("td", {}, fmt(c.chatter_hz, 1)), el("td", { class: "text" }, c.origin), el("td", { class: "text" }, c.recording || ""), el("td", {}, flip));
    }));
}

function renderDetection(r) {
  const box = document.getElementById("detection-result");
  const spectrum = el("div", { class: "chart", id: "spectrum-chart" });
  box.replaceChildren(
    el("h3", {}, "Detection of ", r.file, ": ", el("span", { class: "verdict-" + r.verdict, id: "verdict" }, r.verdict),
      r.chatter_hz ? ` at ${fmt(r.chatter_hz, 1)} Hz` : ""),
    el("p", {}, r.note || ""),
    el("p", {}, "Logged as a cut; overrule it in the table below if you heard otherwise."),
    spectrum);
  const series = [
    { points: r.spectrum, color: "#15c", label: "spectrum" },
    { points: r.harmonics_hz.map(h => [h, 1]), color: "#999", kind: "vline", dash: "2 4", label: "spindle harmonics" },
  ];
  if (r.chatter_hz) series.push({ points: [[r.chatter_hz, 1]], color: "#c00", kind: "vline", label: "chatter frequency" });
  chart(spectrum, {
    xlabel: "frequency (Hz)", ylabel: "normalized density (1/Hz)", logy: true, series,
    hover: x => { const p = nearest(r.spectrum, x); return `${fmt(p[0], 1)} Hz: ${p[1].toPrecision(3)}`; },
  });
}

// ---- learn -----------------------------------------------------------------------------
function renderJobs(d) {
  const t = document.getElementById("job-table");
  t.replaceChildren(el("tr", {}, ["run", "status", "started (UTC)", "finished (UTC)", "note"].map(h => el("th", {}, h))),
    ...d.jobs.map(j => el("tr", {}, el("td", {}, j.id), el("td", { class: "text job-status" }, j.status), el("td", {}, j.created_at),
      el("td", {}, j.finished_at || ""), el("td", { class: "text" }, j.error || (j.result ? j.result.diagnosis.verdict : "")))));
  const done = d.jobs.find(j => j.status === "done");
  if (done && !state.job) renderLearn(done);
  const running = d.jobs.find(j => j.status === "running");
  if (running && !state.poll) follow(running.id);
}

function renderLearn(job) {
  const r = job.result;
  const box = document.getElementById("learn-result");
  const adopt = (which, label) => {
    const b = el("button", { type: "button", id: "adopt-" + which }, label);
    b.onclick = () => run(async () => {
      await postJson(`/api/setups/${state.setup}/adopt`, { job: job.id, which });
      await loadDetail();
      show(`the ${which === "update" ? "updated" : "diagnosed"} model is now the setup's model; its lobes are on the Lobes screen`, "ok");
    });
    return b;
  };
  box.replaceChildren(
    el("h3", {}, `Run ${job.id}: diagnosis `, el("span", { id: "diagnosis-verdict" }, r.diagnosis.verdict.replaceAll("_", " "))),
    el("ul", { class: "plain", id: "diagnosis-summary" }, r.diagnosis.summary.map(t => el("li", {}, t))),
    el("h3", {}, `Updated parameters (${r.observations.cuts} cuts, ${r.observations.poles} poles)`),
    el("table", { id: "update-table" }, el("tr", {}, el("th", {}, "parameter"), el("th", {}, "posterior mean"), el("th", {}, "sd")),
      r.update.parameters.map(p => el("tr", {}, el("td", { class: "text" }, p.name), el("td", {}, p.mean.toPrecision(4)), el("td", {}, p.sd.toPrecision(2))))),
    r.update.warnings.length ? el("ul", {}, r.update.warnings.map(w => el("li", {}, "warning: " + w))) : "",
    adopt("update", "Use the updated model"), " ", adopt("diagnosis", "Use the diagnosed model"));
}

async function follow(id) {
  state.job = id;
  const bar = document.getElementById("job-bar"), stage = document.getElementById("job-stage");
  document.getElementById("job-progress").hidden = false;
  const tick = async () => {
    let r;
    try { r = await api(`/api/jobs/${id}`); } catch (e) { show(e.message); return; }
    const j = r.job;
    if (j.status === "running") {
      const p = r.progress;
      if (p && p.total > 0) { bar.max = p.total; bar.value = p.done; } else { bar.removeAttribute("value"); }
      stage.textContent = p ? `${p.stage}${p.detail ? ", " + p.detail : ""}${p.total ? ` (${p.done}/${p.total})` : ""}${p.cancel_requested ? " — cancelling" : ""}` : "running";
      state.poll = setTimeout(tick, 500);
      return;
    }
    state.poll = null;
    document.getElementById("job-progress").hidden = true;
    if (j.status === "done") { renderLearn(j); show(`run ${id} finished: ${j.result.diagnosis.verdict.replaceAll("_", " ")}`, "ok"); }
    else show(`run ${id} ${j.status}: ${j.error}`, j.status === "cancelled" ? "ok" : "error");
    state.job = null;
    await loadDetail();
  };
  await tick();
}

function renderExport(d) {
  const base = `/api/setups/${d.setup.id}/export/`;
  const links = [["model.json", "the current model (model file)"], ["observations.json", "the cut log and poles (observations file)"]];
  if (d.jobs.some(j => j.status === "done")) links.push(["diagnosis.json", "the latest learning run (posterior summary, diagnosis)"]);
  document.getElementById("export-links").replaceChildren(...links.map(([n, t]) => el("li", {}, el("a", { href: base + n, download: n }, n), " — ", t)));
}

// ---- wiring ----------------------------------------------------------------------------
async function run(f) {
  try { await f(); } catch (e) { show(e.message); }
}

function upload(formId, path, button, done) {
  const form = document.getElementById(formId);
  form.addEventListener("submit", ev => {
    ev.preventDefault();
    run(async () => {
      if (!state.setup) throw new Error("create or choose a setup first");
      const data = new FormData(form);
      const file = data.get("file");
      if (!file || !file.name) throw new Error("file: no file chosen");
      const b = button && document.getElementById(button);
      if (b) b.disabled = true;
      show("working…", "ok");
      try {
        const r = await api(`/api/setups/${state.setup}/${path}`, { method: "POST", body: data });
        await done(r);
      } finally {
        if (b) b.disabled = false;
      }
    });
  });
}

document.querySelectorAll("#tabs button").forEach(b => b.addEventListener("click", () => {
  document.querySelectorAll("#tabs button").forEach(x => x.classList.toggle("active", x === b));
  document.querySelectorAll(".screen").forEach(s => { s.hidden = s.id !== "screen-" + b.dataset.screen; });
  show("");
}));

document.getElementById("setup-select").addEventListener("change", ev => run(async () => {
  state.setup = Number(ev.target.value);
  document.getElementById("learn-result").replaceChildren();
  document.getElementById("lobes-chart").replaceChildren();
  document.getElementById("recommendation").replaceChildren();
  await loadDetail();
}));

document.getElementById("new-setup").addEventListener("submit", ev => {
  ev.preventDefault();
  run(async () => {
    const f = new FormData(ev.target);
    const num = k => (f.get(k) === "" ? null : Number(f.get(k)));
    const r = await postJson("/api/setups", {
      name: f.get("name"), machine: f.get("machine"), tool: f.get("tool"), holder: f.get("holder"),
      teeth: num("teeth"), radial_immersion: num("radial_immersion"), direction: f.get("direction"),
      tool_diameter_mm: num("tool_diameter_mm"), ks_n_per_mm2: num("ks_n_per_mm2"), beta_deg: num("beta_deg"),
    });
    await loadSetups(r.id);
    show(`setup created: now load its tap test`, "ok");
  });
});

upload("frf-form", "frf", "fit-button", async r => {
  await loadDetail();
  show(`fitted ${r.fit.modes.length} mode(s) to ${r.fit.file}; the Lobes screen shows the new model's lobes`, "ok");
});
upload("model-form", "model", null, async () => { await loadDetail(); show("model stored", "ok"); });
upload("recording-form", "recordings", "judge-button", async r => {
  renderDetection(r.detection);
  await loadDetail();
  show(`recording judged ${r.detection.verdict} and logged`, "ok");
});
upload("observations-form", "observations", null, async r => {
  await loadDetail();
  show(`imported ${r.cuts} cuts and ${r.poles} poles`, "ok");
});

document.getElementById("lobes-form").addEventListener("submit", ev => { ev.preventDefault(); run(showLobes); });

document.getElementById("cut-form").addEventListener("submit", ev => {
  ev.preventDefault();
  run(async () => {
    if (!state.setup) throw new Error("create or choose a setup first");
    const f = new FormData(ev.target);
    const num = k => (f.get(k) === "" ? null : Number(f.get(k)));
    await postJson(`/api/setups/${state.setup}/cuts`, {
      speed_rpm: num("speed_rpm"), depth_mm: num("depth_mm"), radial_immersion: num("radial_immersion"),
      stable: f.get("stable") === "true", chatter_hz: num("chatter_hz"),
    });
    await loadDetail();
    show("cut logged", "ok");
  });
});

document.getElementById("learn-form").addEventListener("submit", ev => {
  ev.preventDefault();
  run(async () => {
    if (!state.setup) throw new Error("create or choose a setup first");
    const f = new FormData(ev.target);
    const r = await postJson(`/api/setups/${state.setup}/learn`, {
      seed: Number(f.get("seed")), update_samples: Number(f.get("update_samples")), diagnose_samples: Number(f.get("diagnose_samples")),
    });
    show(`run ${r.job} started`, "ok");
    await loadDetail();
    if (!state.poll) await follow(r.job);
  });
});

document.getElementById("cancel-job").addEventListener("click", () => run(async () => {
  if (state.job) await postJson(`/api/jobs/${state.job}/cancel`, {});
}));

run(() => loadSetups());

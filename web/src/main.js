// canyon dashboard: monitor snapshots arrive by server-sent events (/events) and update Chart.js charts.
// Snapshot schema: include/canyon/dashboard/dashboard.hpp. #test-status carries counters for the browser test.
import {
  Chart, BarController, BarElement, LineController, LineElement, PointElement, ScatterController,
  CategoryScale, LinearScale, Legend, Tooltip,
} from 'chart.js';

Chart.register(BarController, BarElement, LineController, LineElement, PointElement, ScatterController,
  CategoryScale, LinearScale, Legend, Tooltip);

const MAX_POINTS = 600;
const STATUS = { 1: ['fixed', '#2e7d32'], 2: ['float', '#f9a825'], 5: ['single', '#c62828'], 7: ['VIO fill-in', '#6a1b9a'], 8: ['partial fix', '#ef6c00'] };
const PALETTE = ['#1565c0', '#00897b', '#8e24aa', '#ef6c00', '#5d4037', '#3949ab', '#c0ca33', '#d81b60'];
const statusName = (s) => (STATUS[s] ? STATUS[s][0] : (s === undefined ? '-' : `status ${s}`));
const statusColor = (s) => (STATUS[s] ? STATUS[s][1] : '#757575');

const common = { animation: false, responsive: true, maintainAspectRatio: false, parsing: false, normalized: true };
const timeAxis = { type: 'linear', title: { display: true, text: 't (s)' } };

function lineChart(id, datasets, scales = {}) {
  return new Chart(document.getElementById(id), {
    type: 'line',
    data: { datasets: datasets.map((d, i) => ({
      borderColor: PALETTE[i % PALETTE.length], backgroundColor: PALETTE[i % PALETTE.length],
      pointRadius: 0, borderWidth: 1.5, data: [], ...d })) },
    options: { ...common, scales: { x: timeAxis, ...scales } },
  });
}

const charts = {};
charts.stagePct = new Chart(document.getElementById('c-stage-pct'), {
  type: 'bar',
  data: { labels: [], datasets: ['p50', 'p95', 'p99', 'max'].map((q, i) => ({ label: q, data: [], backgroundColor: PALETTE[i] })) },
  options: { animation: false, responsive: true, maintainAspectRatio: false, scales: { y: { type: 'linear', beginAtZero: true } } },
});
charts.latency = lineChart('c-latency', [], { y: { beginAtZero: true } });
charts.age = lineChart('c-age', [
  { label: 'correction age (s)', yAxisID: 'y' },
  { label: 'link loss (%)', yAxisID: 'y1', borderColor: '#c62828', backgroundColor: '#c62828' },
], { y: { beginAtZero: true, position: 'left' }, y1: { beginAtZero: true, position: 'right', grid: { drawOnChartArea: false } } });
charts.sats = lineChart('c-sats', [{ label: 'used', stepped: true }, { label: 'pruned', stepped: true }], { y: { beginAtZero: true } });
charts.status = new Chart(document.getElementById('c-status'), {
  type: 'scatter',
  data: { datasets: [{ label: 'status', data: [], pointRadius: 2, pointBackgroundColor: [] }] },
  options: { ...common, plugins: { legend: { display: false } }, scales: { x: timeAxis,
    y: { min: 0, max: 8, ticks: { stepSize: 1, callback: (v) => (STATUS[v] ? STATUS[v][0] : '') } } } },
});
charts.traj = new Chart(document.getElementById('c-traj'), {
  type: 'scatter',
  data: { datasets: Object.entries(STATUS).map(([s, [name, color]]) => ({ label: name, status: Number(s), data: [], pointRadius: 2, backgroundColor: color })) },
  options: { ...common, scales: { x: { type: 'linear', title: { display: true, text: 'east (m)' } }, y: { type: 'linear', title: { display: true, text: 'north (m)' } } } },
});
charts.align = lineChart('c-align', [
  { label: 'RMSE (m)', yAxisID: 'y' },
  { label: 'eigenvalue ratio', yAxisID: 'y1' },
], { y: { beginAtZero: true, position: 'left' }, y1: { beginAtZero: true, position: 'right', grid: { drawOnChartArea: false } } });
charts.lever = lineChart('c-lever', [{ label: 'x' }, { label: 'y' }, { label: 'z' }]);

const state = { updates: 0, firstT: null, lastT: null, origin: null, prevLinkLost: null, prevLinkPackets: null, stageSets: new Map() };

function push(arr, point) {
  arr.push(point);
  if (arr.length > MAX_POINTS) arr.shift();
}

function num(v) { return typeof v === 'number' && Number.isFinite(v) ? v : null; }

function stageSeries(name) {
  if (!state.stageSets.has(name)) {
    const i = charts.latency.data.datasets.length;
    const ds = { label: name, data: [], borderColor: PALETTE[i % PALETTE.length], backgroundColor: PALETTE[i % PALETTE.length], pointRadius: 0, borderWidth: 1.5 };
    charts.latency.data.datasets.push(ds);
    state.stageSets.set(name, ds);
  }
  return state.stageSets.get(name).data;
}

function sumMatching(obj, pattern) {
  let total = null;
  for (const [k, v] of Object.entries(obj || {})) if (pattern.test(k) && num(v) !== null) total = (total || 0) + v;
  return total;
}

function ingest(s) {
  const t = num(s.t_s);
  if (t === null) return;
  state.updates += 1;
  if (state.firstT === null) state.firstT = t;
  state.lastT = t;

  const stages = s.stages || {};
  for (const [name, p] of Object.entries(stages)) if (num(p && p.p99_us) !== null) push(stageSeries(`${name} p99`), { x: t, y: p.p99_us });
  const e2e = s.end_to_end;
  if (e2e) {
    if (num(e2e.p50_us) !== null) push(stageSeries('end to end p50'), { x: t, y: e2e.p50_us });
    if (num(e2e.p99_us) !== null) push(stageSeries('end to end p99'), { x: t, y: e2e.p99_us });
  }
  const pct = { ...stages };
  if (e2e) pct['end to end'] = e2e;
  charts.stagePct.data.labels = Object.keys(pct);
  ['p50_us', 'p95_us', 'p99_us', 'max_us'].forEach((k, i) => { charts.stagePct.data.datasets[i].data = Object.values(pct).map((p) => num(p && p[k])); });

  const age = num(s.correction_age_s);
  if (age !== null && age >= 0) push(charts.age.data.datasets[0].data, { x: t, y: age });
  const lost = sumMatching(s.drops, /link_lost/);
  const packets = sumMatching(s.drops, /link_packets/);
  if (lost !== null && packets !== null && state.prevLinkLost !== null && packets > state.prevLinkPackets) {
    push(charts.age.data.datasets[1].data, { x: t, y: (100 * (lost - state.prevLinkLost)) / (packets - state.prevLinkPackets) });
  }
  if (lost !== null) { state.prevLinkLost = lost; state.prevLinkPackets = packets; }

  const sol = s.solution;
  if (sol) {
    const pruned = Array.isArray(sol.pruned) ? sol.pruned.length : null;
    if (num(sol.n_sats) !== null) push(charts.sats.data.datasets[0].data, { x: t, y: sol.n_sats });
    if (pruned !== null) push(charts.sats.data.datasets[1].data, { x: t, y: pruned });
    if (num(sol.status) !== null) {
      push(charts.status.data.datasets[0].data, { x: t, y: sol.status });
      const colors = charts.status.data.datasets[0].pointBackgroundColor;
      push(colors, statusColor(sol.status));
    }
    const lat = num(sol.lat_deg);
    const lon = num(sol.lon_deg);
    if (lat !== null && lon !== null) {
      if (!state.origin) state.origin = { lat, lon };
      const east = (lon - state.origin.lon) * (Math.PI / 180) * 6378137 * Math.cos((state.origin.lat * Math.PI) / 180);
      const north = (lat - state.origin.lat) * (Math.PI / 180) * 6378137;
      const ds = charts.traj.data.datasets.find((d) => d.status === sol.status) || charts.traj.data.datasets[2];
      push(ds.data, { x: east, y: north });
    }
    document.getElementById('v-status').textContent = statusName(sol.status);
    document.getElementById('v-status').style.color = statusColor(sol.status);
    document.getElementById('v-sats').textContent = `${sol.n_sats ?? '-'} / ${pruned ?? '-'}`;
    document.getElementById('v-ratio').textContent = num(sol.ratio) !== null ? sol.ratio.toFixed(1) : '-';
    document.getElementById('v-pl').textContent =
      num(sol.hpl_m) !== null ? `${sol.hpl_m.toFixed(2)} / ${num(sol.vpl_m) !== null ? sol.vpl_m.toFixed(2) : '-'} m` : '-';
  }
  const al = s.alignment;
  if (al) {
    if (num(al.rmse_m) !== null) push(charts.align.data.datasets[0].data, { x: t, y: al.rmse_m });
    if (num(al.eigen_ratio) !== null) push(charts.align.data.datasets[1].data, { x: t, y: al.eigen_ratio });
    if (Array.isArray(al.lever_arm_m) && al.lever_arm_m.length === 3) al.lever_arm_m.forEach((v, i) => { if (num(v) !== null) push(charts.lever.data.datasets[i].data, { x: t, y: v }); });
  }
  document.getElementById('v-t').textContent = `${t.toFixed(1)} s`;
  document.getElementById('v-age').textContent = age !== null && age >= 0 ? `${age.toFixed(2)} s` : '-';
  document.getElementById('v-e2e').textContent = e2e && num(e2e.p99_us) !== null ? `${e2e.p99_us.toFixed(0)} us` : '-';
  const drops = Object.entries(s.drops || {}).filter(([k]) => !/link_packets/.test(k)).reduce((a, [, v]) => a + (num(v) || 0), 0);
  document.getElementById('v-drops').textContent = String(drops);
  document.getElementById('v-count').textContent = String(state.updates);
}

/// Canvases with drawn pixels (sampled), for the browser test.
function drawnCharts() {
  let drawn = 0;
  for (const c of Object.values(charts)) {
    const ctx = c.canvas.getContext('2d');
    const { width, height } = c.canvas;
    if (!width || !height) continue;
    const px = ctx.getImageData(0, 0, width, height).data;
    let ink = 0;
    for (let i = 3; i < px.length; i += 4 * 7) if (px[i] !== 0) ink += 1;
    if (ink > 50) drawn += 1;
  }
  return drawn;
}

let pending = false;
function render() {
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => {
    pending = false;
    for (const c of Object.values(charts)) c.update('none');
    const el = document.getElementById('test-status');
    el.dataset.updates = String(state.updates);
    el.dataset.firstT = String(state.firstT);
    el.dataset.lastT = String(state.lastT);
    el.dataset.charts = String(Object.keys(charts).length);
    el.dataset.drawn = String(drawnCharts());
    el.dataset.protection = document.getElementById('v-pl').textContent;
  });
}

function connect() {
  const link = document.getElementById('link');
  const es = new EventSource('events');
  es.addEventListener('history', (e) => {
    try { JSON.parse(e.data).forEach(ingest); } catch (err) { console.error('bad history', err); }
    render();
  });
  es.onmessage = (e) => {
    try { ingest(JSON.parse(e.data)); } catch (err) { console.error('bad snapshot', err); }
    render();
  };
  es.onopen = () => { link.textContent = 'live'; link.className = ''; };
  es.onerror = () => { link.textContent = 'disconnected, retrying...'; link.className = 'down'; };
}

connect();

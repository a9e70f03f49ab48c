// The `fignet compare` report's player: every run of a scene side by side in one WebGL canvas
// (one viewport per run, one shared camera), error-over-time plots and the speed-accuracy chart.
// Bundled with three.js by esbuild at build time (tools/CMakeLists.txt) into the report itself.
// window.fignetReport exposes the player's state to the headless-browser test.
import * as THREE from 'three';

const data = JSON.parse(document.getElementById('report-data').textContent);
const app = document.getElementById('app');
const state = { scene: 0, frame: 0, playing: true, ready: false, framesShown: 0 };
window.fignetReport = state;

const palette = ['#222222', '#d62728', '#1f77b4', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b'];
const colorOf = (i) => palette[i % palette.length];

// ---- layout ------------------------------------------------------------------------------
function element(tag, attributes = {}, parent = app) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attributes)) {
    if (k === 'text') e.textContent = v;
    else e.setAttribute(k, v);
  }
  parent.appendChild(e);
  return e;
}

element('h2', { text: 'Side by side' });
const controls = element('div', { style: 'margin-bottom: 0.5em' });
const sceneSelect = element('select', { id: 'scene' }, controls);
data.scenes.forEach((_, i) => element('option', { value: i, text: `scene ${i + 1}` }, sceneSelect));
const playButton = element('button', { id: 'play', text: 'pause', style: 'margin: 0 0.5em' },
                           controls);
const slider = element('input', { id: 'frame', type: 'range', min: 0, value: 0,
                                  style: 'width: 30em; vertical-align: middle' }, controls);
const frameLabel = element('span', { style: 'margin-left: 0.5em' }, controls);
const canvas = element('canvas', { id: 'player', width: 1200, height: 620,
                                   style: 'width: 100%; max-width: 1200px; background: #fff' });

// ---- 3D: one viewport per run -----------------------------------------------------------------
const runs = data.runs;
const columns = Math.min(runs.length, 3);
const rows = Math.ceil(runs.length / columns);
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setScissorTest(true);
const camera = new THREE.PerspectiveCamera(40, (canvas.width / columns) / (canvas.height / rows),
                                          0.05, 200);
camera.up.set(0, 0, 1);
const views = runs.map((run, r) => {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(r === 0 ? '#f4f4f4' : '#ffffff');
  scene.add(new THREE.HemisphereLight('#ffffff', '#667788', 2.0));
  const sun = new THREE.DirectionalLight('#ffffff', 1.5);
  sun.position.set(3, -4, 8);
  scene.add(sun);
  return { run, scene, bodies: [] };
});

function buildScene(index) {
  const spec = data.scenes[index];
  let lo = new THREE.Vector3(Infinity, Infinity, Infinity);
  let hi = new THREE.Vector3(-Infinity, -Infinity, -Infinity);
  views.forEach((view, r) => {
    view.bodies.forEach((b) => view.scene.remove(b));
    view.bodies = spec.objects.map((object, o) => {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.Float32BufferAttribute(object.vertices, 3));
      geometry.setIndex(object.faces);
      geometry.computeVertexNormals();
      const hue = (o * 0.137) % 1;
      const material = new THREE.MeshStandardMaterial({
        color: object.kinematic ? '#888888' : new THREE.Color().setHSL(hue, 0.55, 0.55),
        flatShading: true,
      });
      const mesh = new THREE.Mesh(geometry, material);
      view.scene.add(mesh);
      return mesh;
    });
    if (spec.floor !== null && !view.floor) {
      view.floor = new THREE.GridHelper(20, 20, '#999999', '#dddddd');
      view.floor.rotation.x = Math.PI / 2;
      view.scene.add(view.floor);
    }
    if (view.floor) view.floor.position.z = spec.floor ?? 0;
    // Frame the camera on the ground truth's whole trajectory.
    if (r === 0) {
      const poses = view.run.poses[index];
      for (let i = 0; i < poses.length; i += 7) {
        const p = new THREE.Vector3(poses[i], poses[i + 1], poses[i + 2]);
        lo.min(p);
        hi.max(p);
      }
    }
  });
  const center = lo.clone().add(hi).multiplyScalar(0.5);
  const size = Math.max(2, hi.clone().sub(lo).length());
  camera.position.set(center.x + 0.9 * size, center.y - 1.2 * size, center.z + 0.8 * size);
  camera.lookAt(center);
  slider.max = spec.frames - 1;
}

function showFrame() {
  const objects = data.scenes[state.scene].objects.length;
  views.forEach((view) => {
    const poses = view.run.poses[state.scene];
    const frame = Math.min(state.frame, poses.length / (7 * objects) - 1);
    view.bodies.forEach((mesh, o) => {
      const i = (frame * objects + o) * 7;
      mesh.position.set(poses[i], poses[i + 1], poses[i + 2]);
      mesh.quaternion.set(poses[i + 3], poses[i + 4], poses[i + 5], poses[i + 6]);
    });
  });
  const w = canvas.width / columns;
  const h = canvas.height / rows;
  views.forEach((view, r) => {
    const x = (r % columns) * w;
    const y = canvas.height - (Math.floor(r / columns) + 1) * h;
    renderer.setViewport(x, y, w, h);
    renderer.setScissor(x, y, w, h);
    renderer.render(view.scene, camera);
  });
  slider.value = state.frame;
  const seconds = (state.frame * data.frame_step_s).toFixed(2);
  frameLabel.textContent = `frame ${state.frame} (${seconds} s)`;
  state.framesShown += 1;
}

// Run names over their viewports.
const labels = element('div', { style: 'position: relative; max-width: 1200px' });
labels.appendChild(canvas);
views.forEach((view, r) => {
  const tag = element('div', {
    text: `${view.run.name} (${view.run.kind})`,
    style: `position: absolute; left: ${(100 * (r % columns)) / columns}%; ` +
           `top: ${(100 * Math.floor(r / columns)) / rows}%; padding: 0.2em 0.5em; ` +
           `font-size: 0.9em; color: ${colorOf(r)}`,
  }, labels);
  tag.className = 'view-label';
});

sceneSelect.onchange = () => {
  state.scene = Number(sceneSelect.value);
  state.frame = 0;
  buildScene(state.scene);
  showFrame();
};
playButton.onclick = () => {
  state.playing = !state.playing;
  playButton.textContent = state.playing ? 'pause' : 'play';
};
slider.oninput = () => {
  state.frame = Number(slider.value);
  showFrame();
};

let last = 0;
function tick(time) {
  const frames = data.scenes[state.scene].frames;
  if (state.playing && time - last >= 1000 * data.frame_step_s) {
    last = time;
    state.frame = (state.frame + 1) % frames;
    showFrame();
  }
  requestAnimationFrame(tick);
}

// ---- plots (SVG) ----------------------------------------------------------------------------
const svgNS = 'http://www.w3.org/2000/svg';
function svg(tag, attributes, parent) {
  const e = document.createElementNS(svgNS, tag);
  for (const [k, v] of Object.entries(attributes)) {
    if (k === 'text') e.textContent = v;
    else e.setAttribute(k, v);
  }
  parent.appendChild(e);
  return e;
}

// A line or scatter chart; `series` = [{name, color, points: [[x, y], ...], line}].
function chart(title, xLabel, yLabel, series, { logX = false, id } = {}) {
  const width = 560, height = 320, left = 60, right = 20, top = 30, bottom = 45;
  const root = svg('svg', { width, height, id, style: 'background: #fff; margin: 0.5em' },
                   app);
  const all = series.flatMap((s) => s.points).filter(([x, y]) => isFinite(x) && isFinite(y));
  const fx = (x) => (logX ? Math.log10(Math.max(x, 1e-9)) : x);
  let [x0, x1] = [Math.min(...all.map(([x]) => fx(x))), Math.max(...all.map(([x]) => fx(x)))];
  let [y0, y1] = [0, Math.max(...all.map(([, y]) => y))];
  if (x1 === x0) { x0 -= 1; x1 += 1; }
  if (logX) { x0 = Math.floor(x0); x1 = Math.ceil(x1); }
  if (y1 === 0) y1 = 1;
  const px = (x) => left + ((fx(x) - x0) / (x1 - x0)) * (width - left - right);
  const py = (y) => height - bottom - (y / y1) * (height - top - bottom);
  svg('text', { x: left, y: 18, text: title, 'font-weight': 'bold', 'font-size': 14 }, root);
  svg('line', { x1: left, y1: height - bottom, x2: width - right, y2: height - bottom,
                stroke: '#444' }, root);
  svg('line', { x1: left, y1: top, x2: left, y2: height - bottom, stroke: '#444' }, root);
  for (let i = 0; i <= 4; ++i) {
    const y = (y1 * i) / 4;
    svg('text', { x: left - 6, y: py(y) + 4, text: y.toPrecision(2), 'text-anchor': 'end',
                  'font-size': 11 }, root);
    const xv = x0 + ((x1 - x0) * i) / 4;
    const label = logX ? (10 ** xv).toPrecision(2) : xv.toPrecision(3);
    svg('text', { x: left + ((xv - x0) / (x1 - x0)) * (width - left - right), y: height - bottom + 16,
                  text: label, 'text-anchor': 'middle', 'font-size': 11 }, root);
  }
  svg('text', { x: (left + width - right) / 2, y: height - 8, text: xLabel,
                'text-anchor': 'middle', 'font-size': 12 }, root);
  svg('text', { x: 14, y: (top + height - bottom) / 2, text: yLabel, 'font-size': 12,
                transform: `rotate(-90 14 ${(top + height - bottom) / 2})`,
                'text-anchor': 'middle' }, root);
  series.forEach((s, i) => {
    const points = s.points.filter(([x, y]) => isFinite(x) && isFinite(y));
    if (s.line) {
      svg('polyline', { points: points.map(([x, y]) => `${px(x)},${py(y)}`).join(' '),
                        fill: 'none', stroke: s.color, 'stroke-width': 1.8 }, root);
      svg('text', { x: width - right - 4, y: top + 14 * i, text: s.name, fill: s.color,
                    'text-anchor': 'end', 'font-size': 11 }, root);
    } else {
      // Scatter points carry their own names (a legend would cover the costliest point).
      points.forEach(([x, y]) => {
        svg('circle', { cx: px(x), cy: py(y), r: 5, fill: s.color }, root);
        const rightHalf = px(x) > (left + width - right) / 2;
        svg('text', { x: px(x) + (rightHalf ? -8 : 8), y: py(y) - 8, text: s.name,
                      fill: s.color, 'text-anchor': rightHalf ? 'end' : 'start',
                      'font-size': 11 }, root);
      });
    }
  });
  return root;
}

function plots() {
  element('h2', { text: 'Error over time (mean over scenes)' });
  const timeSeries = (key) => runs.slice(1).map((run, i) => ({
    name: run.name, color: colorOf(i + 1), line: true,
    points: run[key].map((y, f) => [f * data.frame_step_s, y]),
  }));
  chart('Translation error', 'time (s)', 'metres', timeSeries('translation_per_frame_m'),
        { id: 'translation-plot' });
  chart('Rotation error', 'time (s)', 'degrees', timeSeries('rotation_per_frame_deg'),
        { id: 'rotation-plot' });
  element('h2', { text: 'Speed and accuracy' });
  chart('Cost against error (lower left is better)', 'ms per simulated second (log)',
        'mean translation error (m)',
        runs.map((run, i) => ({
          name: run.name, color: colorOf(i), line: false,
          points: [[run.ms_per_simulated_second, run.mean_translation_m]],
        })), { logX: true, id: 'speed-accuracy' });
}

buildScene(0);
showFrame();
plots();
state.ready = true;
requestAnimationFrame(tick);

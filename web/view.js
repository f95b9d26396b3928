// The page of `femdyn view` (docs/view.md): draws the scene femdyn wrote (view/scene.hpp) with
// three.js and plays its motion. The poses come computed from femdyn: this script only places
// each body's group at its pose (interpolated between frames) and draws.
(function () {
  'use strict';
  const data = JSON.parse(document.getElementById('femdyn-scene').textContent);
  const statusBox = document.getElementById('femdyn-status');
  const motion = data.motion;
  const nb = data.bodies.length;

  // ---- Sizes and colours -------------------------------------------------------------------
  const v3 = (a) => new THREE.Vector3(a[0], a[1], a[2]);
  const quat = (a) => new THREE.Quaternion(a[0], a[1], a[2], a[3]);
  const bodyColor = (b) => (b < 0 ? new THREE.Color(0x888888)
                                  : new THREE.Color().setHSL((b * 0.618034) % 1, 0.65, 0.5));

  function poseOf(frame, b) {
    const p = motion.poses[frame];
    return { p: new THREE.Vector3(p[7 * b], p[7 * b + 1], p[7 * b + 2]),
             q: new THREE.Quaternion(p[7 * b + 3], p[7 * b + 4], p[7 * b + 5], p[7 * b + 6]) };
  }
  // A point fixed on body b (-1: the world) at a frame, in world coordinates.
  function worldPoint(frame, b, p) {
    if (b < 0) return v3(p);
    const pose = poseOf(frame, b);
    return v3(p).applyQuaternion(pose.q).add(pose.p);
  }

  // The model's extent at every frame: body origins, element nodes, and each visual's bounding
  // sphere (its radius about its origin, meshes included) at the first frame.
  const extent = new THREE.Box3();
  for (let f = 0; f < motion.t.length; ++f)
    for (let b = 0; b < nb; ++b) extent.expandByPoint(poseOf(f, b).p);
  for (const e of data.elements)
    for (const n of e.nodes) extent.expandByPoint(worldPoint(0, n.body, n.p));
  for (const v of data.visuals) {
    const d = 2 * (v.radius || 0);
    extent.union(new THREE.Box3().setFromCenterAndSize(worldPoint(0, v.body, v.p),
                                                        new THREE.Vector3(d, d, d)));
  }
  extent.expandByPoint(new THREE.Vector3());
  const L = Math.max(extent.getSize(new THREE.Vector3()).length(), 0.05);
  const R0 = 0.035 * L;  // the largest element marker
  const maxMass = Math.max(1e-12, ...data.elements.map((e) => e.mass));
  const maxMoment = Math.max(1e-12, ...data.elements.map((e) => Math.max(...e.moments)));

  // ---- Scene -------------------------------------------------------------------------------
  const container = document.getElementById('view3d');
  // Without WebGL (a browser or a headless run without it) the page still holds the scene, its
  // legends and its plots, and says in the 3-D view why nothing is drawn there.
  let renderer = null;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    container.appendChild(renderer.domElement);
  } catch (e) {
    const note = document.createElement('div');
    note.id = 'no-webgl';
    note.textContent = 'This browser gives the page no WebGL, so the 3-D view is not drawn ' +
        '(' + (e && e.message ? e.message : e) + '); the legends and plots still are. In ' +
        'headless Chromium, --use-angle=swiftshader --enable-unsafe-swiftshader gives WebGL.';
    container.appendChild(note);
  }
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f6f8);
  const g = v3(data.gravity);
  const up = g.lengthSq() > 0 ? g.clone().negate().normalize() : new THREE.Vector3(0, 0, 1);
  const camera = new THREE.PerspectiveCamera(40, 1, L * 1e-3, L * 100);
  camera.up.copy(up);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.copy(up.clone().multiplyScalar(2 * L).add(new THREE.Vector3(L, L, 0)));
  scene.add(sun);

  const pickable = [];  // meshes named on hover
  const counts = { bodies: 0, joints: 0, elements: 0, frames: 0, visuals: 0, meshes: 0,
                   not_drawn: 0, inertia_boxes: 0, constraints: 0, bars: 0 };
  // What each toggle shows or hides (the side panel's check boxes).
  const layers = { visuals: [], elements: [], frames: [], joints: [], inertia: [], constraints: [] };
  function inLayer(layer, object) { layers[layer].push(object); return object; }
  const material = (color, opacity) => new THREE.MeshStandardMaterial(
      { color: color, roughness: 0.55, metalness: 0.1, transparent: opacity < 1,
        opacity: opacity === undefined ? 1 : opacity,
        side: THREE.DoubleSide });  // a mirrored mesh (negative scale) turns its faces inside out
  function labelled(object, label) {  // a mesh, or each mesh of a group (a Collada file)
    object.traverse((o) => {
      if (!o.isMesh) return;
      o.userData.label = label;
      pickable.push(o);
    });
    return object;
  }

  // One group per body, placed at the body's pose; the world's group stays put.
  const world = new THREE.Group();
  scene.add(world);
  const groups = data.bodies.map(() => new THREE.Group());
  groups.forEach((grp) => world.add(grp));
  const groupOf = (b) => (b < 0 ? world : groups[b]);
  const bodyName = (b) => (b < 0 ? 'world' : data.bodies[b].name);
  counts.bodies = groups.length;

  // The body frames, and the links: parent origin to the joint's origin, in the parent's colour.
  data.bodies.forEach((body, b) => {
    const axes = new THREE.AxesHelper(0.06 * L);
    groups[b].add(inLayer('joints', axes));
    const link = new THREE.BufferGeometry().setFromPoints(
        [new THREE.Vector3(), v3(body.joint.origin)]);
    const linkMaterial = new THREE.LineBasicMaterial({ color: bodyColor(body.parent) });
    groupOf(body.parent).add(inLayer('joints', new THREE.Line(link, linkMaterial)));
  });

  // The joints and their axes (in the body frame: the joint frame after its motion).
  const jointColor = new THREE.Color(0x505860);
  function axisArrow(axis, color) {
    return new THREE.ArrowHelper(v3(axis).normalize(), new THREE.Vector3(), 0.1 * L, color,
                                 0.025 * L, 0.012 * L);
  }
  data.bodies.forEach((body, b) => {
    const j = body.joint;
    if (j.type === 'fixed') return;
    counts.joints += 1;
    const label = `joint ${j.name} (${j.type}) of ${body.name}`;
    if (['revolute', 'prismatic', 'helical', 'universal', 'planar'].includes(j.type))
      groups[b].add(inLayer('joints', axisArrow(j.axis, jointColor)));
    if (j.type === 'universal') groups[b].add(inLayer('joints', axisArrow(j.axis2, 0x7a4a00)));
    const marker = new THREE.Mesh(new THREE.SphereGeometry(0.007 * L, 12, 8), material(jointColor));
    groups[b].add(inLayer('joints', labelled(marker, label)));
  });

  // Named frames: a smaller triad at their place on their body.
  for (const fr of data.frames) {
    const grp = new THREE.Group();
    grp.position.copy(v3(fr.p));
    grp.quaternion.copy(quat(fr.quaternion));
    grp.add(new THREE.AxesHelper(0.05 * L));
    const dot = new THREE.Mesh(new THREE.SphereGeometry(0.01 * L, 8, 6), material(0x222222));
    grp.add(labelled(dot, `frame ${fr.name} on ${bodyName(fr.body)}`));
    groupOf(fr.body).add(inLayer('frames', grp));
    counts.frames += 1;
  }

  // ---- Elements as the method sees them ----------------------------------------------------
  const spanning = [];  // bars whose nodes lie on two bodies: placed again at every frame
  const unitCylinder = new THREE.CylinderGeometry(1, 1, 1, 16);
  function bar(mesh, a, b, radius) {  // the unit cylinder (along y) from a to b
    const d = b.clone().sub(a);
    mesh.position.copy(a).addScaledVector(d, 0.5);
    mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), d.clone().normalize());
    mesh.scale.set(radius, Math.max(d.length(), 1e-9), radius);
  }
  const massRadius = (m) => R0 * Math.max(0.25, Math.cbrt(m / maxMass));
  function elementMesh(e) {
    const color = bodyColor(e.body);
    const n0 = e.nodes[0];
    if (e.type === 'lumped_point' || e.type === 'rigid_body') {
      const sphere = new THREE.SphereGeometry(massRadius(e.mass), 20, 14);
      const mesh = new THREE.Mesh(sphere, material(color));
      mesh.position.copy(v3(e.type === 'lumped_point' ? n0.p : e.com));
      return mesh;
    }
    if ((e.type === 'space_bar' || e.type === 'rod') && e.nodes.length >= 2) {
      const mesh = new THREE.Mesh(unitCylinder, material(color));
      const radius = 0.4 * massRadius(e.mass);
      const [a, b] = e.nodes;
      if (a.body === e.body && b.body === e.body) bar(mesh, v3(a.p), v3(b.p), radius);
      else {
        spanning.push({ mesh: mesh, a: a, b: b, radius: radius });
        mesh.userData.spans = true;
      }
      return mesh;
    }
    if (e.type === 'rotary_node') {  // a disc normal to the axis of the largest moment
      const r = 1.4 * R0 * Math.max(0.3, Math.pow(Math.max(...e.moments) / maxMoment, 0.2));
      const disc = new THREE.CylinderGeometry(r, r, 0.08 * r, 32).rotateX(Math.PI / 2);
      const mesh = new THREE.Mesh(disc, material(color.clone().offsetHSL(0, 0, -0.15)));
      mesh.position.copy(v3(n0 ? n0.p : e.com));
      mesh.quaternion.copy(quat(e.axes));
      return mesh;
    }
    const mesh = new THREE.Mesh(new THREE.OctahedronGeometry(massRadius(e.mass)), material(color));
    mesh.position.copy(v3(e.com));
    return mesh;
  }
  const nodeGeometry = new THREE.SphereGeometry(0.005 * L, 8, 6);
  const nodeMaterial = material(0x111111);
  const nodesSeen = new Set();
  data.elements.forEach((e, k) => {
    const amount = e.type === 'rotary_node' ? `I ${Math.max(...e.moments).toPrecision(3)} kg·m²`
                                            : `${e.mass.toPrecision(3)} kg`;
    const label = `${bodyName(e.body)}: ${e.type} #${k}, ${amount}`;
    const mesh = inLayer('elements', labelled(elementMesh(e), label));
    (mesh.userData.spans ? world : groupOf(e.body)).add(mesh);
    counts.elements += 1;
    for (const n of e.nodes) {  // the nodes each element uses, once per place
      const key = `${n.body}:${n.p.join(',')}`;
      if (nodesSeen.has(key)) continue;
      nodesSeen.add(key);
      const dot = new THREE.Mesh(nodeGeometry, nodeMaterial);
      dot.position.copy(v3(n.p));
      groupOf(n.body).add(inLayer('elements',
                                  labelled(dot, `node ${n.label || ''} on ${bodyName(n.body)}`)));
    }
  });

  // ---- The robot file's visuals, and each body without any as its inertia box ------------
  function bytesOf(b64) {
    const text = atob(b64), out = new Uint8Array(text.length);
    for (let i = 0; i < text.length; ++i) out[i] = text.charCodeAt(i);
    return out.buffer;
  }
  // A Collada mesh is three.js's parse of its text: a group, turned back to the file's own axes
  // (the loader turns a Z_UP file to three.js's Y_UP; robot files mean the link's frame).
  function colladaGroup(m) {
    const parsed = new THREE.ColladaLoader().parse(m.collada, '');
    if (!parsed || !parsed.scene) throw new Error('a Collada mesh three.js cannot read');
    parsed.scene.rotation.set(0, 0, 0);
    parsed.scene.scale.multiply(v3(m.scale));
    counts.meshes += 1;
    return parsed.scene;
  }
  const meshGeometries = (data.meshes || []).map((m) => {
    if (m.collada !== undefined) return { collada: colladaGroup(m) };
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position',
                          new THREE.BufferAttribute(new Float32Array(bytesOf(m.positions)), 3));
    geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(bytesOf(m.indices)), 1));
    geometry.computeVertexNormals();
    counts.meshes += 1;
    return geometry;
  });
  function visualGeometry(v) {  // three.js's round shapes lie along y, the files' along z
    const s = v.size;
    if (v.shape === 'box') return new THREE.BoxGeometry(s[0], s[1], s[2]);
    if (v.shape === 'cylinder')
      return new THREE.CylinderGeometry(s[0], s[0], s[1], 24).rotateX(Math.PI / 2);
    if (v.shape === 'capsule')
      return new THREE.CapsuleGeometry(s[0], s[1], 6, 16).rotateX(Math.PI / 2);
    if (v.shape === 'sphere') return new THREE.SphereGeometry(s[0], 24, 16);
    if (v.shape === 'ellipsoid') return new THREE.SphereGeometry(1, 24, 16).scale(s[0], s[1], s[2]);
    if (v.shape === 'mesh' && v.mesh >= 0) return meshGeometries[v.mesh];
    return null;
  }
  for (const v of data.visuals) {
    const geometry = visualGeometry(v);
    if (!geometry) continue;  // listed in data.not_drawn, with why
    const color = v.rgba ? new THREE.Color(v.rgba[0], v.rgba[1], v.rgba[2]) : bodyColor(v.body);
    const paint = material(color, v.shape === 'mesh' ? 0.8 : 0.45);
    let mesh;
    if (geometry.collada) {  // its own meshes, in the visual's colour
      mesh = geometry.collada.clone();
      mesh.traverse((o) => { if (o.isMesh) o.material = paint; });
    } else {
      mesh = new THREE.Mesh(geometry, paint);
    }
    mesh.position.copy(v3(v.p));
    mesh.quaternion.copy(quat(v.quaternion));
    const what = v.shape === 'mesh' ? `mesh ${v.file}` : v.shape;
    groupOf(v.body).add(inLayer('visuals', labelled(mesh, `${v.link}: visual ${what}`)));
    counts.visuals += 1;
  }
  counts.not_drawn = (data.not_drawn || []).length;
  for (const box of data.inertia_boxes || []) {
    const mesh = new THREE.Mesh(new THREE.BoxGeometry(box.size[0], box.size[1], box.size[2]),
                                material(bodyColor(box.body), 0.3));
    mesh.position.copy(v3(box.com));
    mesh.quaternion.copy(quat(box.quaternion));
    groups[box.body].add(inLayer('inertia',
                                 labelled(mesh, `${bodyName(box.body)}: its inertia box`)));
    counts.inertia_boxes += 1;
  }

  // ---- Loop constraints: a line between each one's two places, placed again at every frame --
  const closures = [];
  const closureMaterial = new THREE.LineDashedMaterial({ color: 0xd62728, dashSize: 0.02 * L,
                                                          gapSize: 0.01 * L });
  for (const c of data.constraints || []) {
    const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(
        [new THREE.Vector3(), new THREE.Vector3()]), closureMaterial);
    world.add(inLayer('constraints', line));
    const ends = [c.a, c.b].map((end) => {
      const dot = new THREE.Mesh(new THREE.SphereGeometry(0.01 * L, 10, 8), material(0xd62728));
      dot.position.copy(v3(end.p));
      groupOf(end.body).add(inLayer('constraints', labelled(dot, `constraint ${c.name} (${c.type})`)));
      return dot;
    });
    closures.push({ line: line, ends: ends });
    counts.constraints += 1;
  }

  // ---- Flexible bars: a tube through each bar's stations (the clamp, each part's joint, the
  // tip), built again at every frame, so that the bar bends as its pieces turn -----------------
  const bars = [];
  for (const b of data.bars || []) {
    const mesh = new THREE.Mesh(new THREE.BufferGeometry(), material(0x9aa3ad));
    const parts = b.stations.length - 2;
    const ends = `${bodyName(b.stations[0])} to ${bodyName(b.stations[parts + 1])}`;
    world.add(inLayer('visuals', labelled(mesh, `flexible bar ${b.name} (${parts} parts, ${ends})`)));
    // (its geometry is in world coordinates: where it is on the screen is its middle station)
    const middle = b.stations[Math.floor(b.stations.length / 2)];
    mesh.userData.anchor = () => groups[middle].getWorldPosition(new THREE.Vector3());
    bars.push({ mesh: mesh, stations: b.stations, radius: Math.max(b.radius, 0.002 * L) });
    counts.bars += 1;
  }
  function shapeBar(bar) {
    const points = bar.stations.map((s) => groups[s].getWorldPosition(new THREE.Vector3()));
    const curve = new THREE.CatmullRomCurve3(points, false, 'centripetal');
    bar.mesh.geometry.dispose();
    bar.mesh.geometry = new THREE.TubeGeometry(curve, 4 * (points.length - 1), bar.radius, 12,
                                               false);
  }

  // ---- Summary, legends, toggles -------------------------------------------------------------
  document.getElementById('model-name').textContent = `${data.model} (${data.source})`;
  document.getElementById('summary').textContent =
      `${counts.bodies} bodies, ${counts.joints} moving joints, ${counts.elements} elements, ` +
      `${counts.frames} named frames, ${counts.visuals} visuals (${counts.meshes} meshes), ` +
      `${counts.constraints} loop constraints` +
      (counts.bars ? `, ${counts.bars} flexible bars` : '') +
      (counts.inertia_boxes ? `, ${counts.inertia_boxes} bodies drawn as their inertia box` : '') +
      (motion.trajectory ? `; ${motion.t.length} frames` : '; one posture');
  const notDrawn = document.getElementById('not-drawn');
  for (const n of data.not_drawn || []) {
    const row = document.createElement('div');
    row.textContent = `${n.link}: ${n.mesh}: ${n.why}`;
    notDrawn.append(row);
  }
  notDrawn.hidden = counts.not_drawn === 0;
  notDrawn.querySelector('summary').textContent = `${counts.not_drawn} meshes not drawn`;
  function swatchRow(color, text) {
    const row = document.createElement('div');
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = color;
    row.append(swatch, document.createTextNode(text));
    return row;
  }
  const bodyLegend = document.getElementById('body-legend');
  bodyLegend.querySelector('summary').textContent = `bodies (${nb})`;
  data.bodies.forEach((body, b) => bodyLegend.append(swatchRow('#' + bodyColor(b).getHexString(),
                                                                 body.name)));
  for (const name of Object.keys(layers)) {
    const box = document.getElementById('show-' + name);
    box.disabled = layers[name].length === 0;
    box.addEventListener('change', () => {
      for (const object of layers[name]) object.visible = box.checked;
      if (!state.playing) show();
    });
  }

  // ---- Motion --------------------------------------------------------------------------------
  const T = motion.t;
  const t0 = T[0], t1 = T[T.length - 1];
  const state = { t: t0, playing: motion.trajectory && T.length > 1, speed: 1, loop: true };
  function frameAt(t) {  // the last frame at or before t (binary search)
    let lo = 0, hi = T.length - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (T[mid] <= t) lo = mid; else hi = mid - 1;
    }
    return lo;
  }
  function placeBodies(t) {
    const f = frameAt(t), f2 = Math.min(f + 1, T.length - 1);
    const s = f2 > f && T[f2] > T[f] ? (t - T[f]) / (T[f2] - T[f]) : 0;
    for (let b = 0; b < nb; ++b) {
      const a = poseOf(f, b), c = poseOf(f2, b);
      groups[b].position.copy(a.p.lerp(c.p, s));
      groups[b].quaternion.copy(a.q.slerp(c.q, s));
    }
    world.updateMatrixWorld(true);
    for (const sp of spanning)
      bar(sp.mesh, groupOf(sp.a.body).localToWorld(v3(sp.a.p)),
          groupOf(sp.b.body).localToWorld(v3(sp.b.p)), sp.radius);
    for (const b of bars) shapeBar(b);
    for (const c of closures) {
      c.line.geometry.setFromPoints(c.ends.map((dot) => dot.getWorldPosition(new THREE.Vector3())));
      c.line.computeLineDistances();
    }
  }

  // ---- Plots: the coordinates and the energy balance against time ----------------------------
  const palette = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#17becf', '#8c564b',
                   '#e377c2', '#7f7f7f', '#bcbd22'];
  const energy = motion.energy;
  const total = energy.kinetic.map((k, i) => k + energy.potential[i]);
  const balance = total.map((e, i) => e - energy.work[i]);
  const plots = [
    { canvas: document.getElementById('plot-q'), legend: document.getElementById('q-legend'),
      series: data.coordinates.map((name, i) => ({ name: name, y: motion.q.map((q) => q[i]) })) },
    { canvas: document.getElementById('plot-energy'),
      legend: document.getElementById('energy-legend'),
      series: [{ name: 'kinetic', y: energy.kinetic }, { name: 'potential', y: energy.potential },
               { name: 'total E', y: total }, { name: 'E − W', y: balance }] },
  ];
  // Each plot's legend holds every series: a click hides or shows one.
  for (const plot of plots) {
    plot.legend.querySelector('summary').textContent += ` (${plot.series.length})`;
    plot.series.forEach((s, i) => {
      const row = swatchRow(palette[i % palette.length], s.name);
      row.className = 'series';
      row.addEventListener('click', () => {
        s.hidden = !s.hidden;
        row.classList.toggle('off', !!s.hidden);
        drawPlot(plot, state.t);
      });
      plot.legend.append(row);
    });
  }
  function drawPlot(plot, t) {
    const c = plot.canvas, ratio = window.devicePixelRatio || 1;
    c.width = c.clientWidth * ratio;
    c.height = c.clientHeight * ratio;
    const ctx = c.getContext('2d');
    ctx.scale(ratio, ratio);
    const w = c.clientWidth, h = c.clientHeight, m = 6;
    let lo = Infinity, hi = -Infinity;
    const shown = plot.series.filter((s) => !s.hidden);
    for (const s of shown)
      for (const y of s.y) {
        lo = Math.min(lo, y);
        hi = Math.max(hi, y);
      }
    if (!(hi > lo)) { lo -= 1; hi += 1; }
    const span = t1 > t0 ? t1 - t0 : 1;
    const X = (x) => m + (w - 2 * m) * (x - t0) / span;
    const Y = (y) => h - m - (h - 2 * m) * (y - lo) / (hi - lo);
    ctx.font = '10px sans-serif';
    plot.series.forEach((s, i) => {
      if (s.hidden) return;
      ctx.strokeStyle = ctx.fillStyle = palette[i % palette.length];
      ctx.beginPath();
      s.y.forEach((y, k) => (k ? ctx.lineTo(X(T[k]), Y(y)) : ctx.moveTo(X(T[k]), Y(y))));
      if (T.length === 1) ctx.arc(X(T[0]), Y(s.y[0]), 2, 0, 2 * Math.PI);
      ctx.stroke();
    });
    ctx.fillStyle = '#555';
    ctx.fillText(hi.toPrecision(3), m, 10);
    ctx.fillText(lo.toPrecision(3), m, h - m);
    ctx.strokeStyle = '#000';
    ctx.beginPath();
    ctx.moveTo(X(t), m);
    ctx.lineTo(X(t), h - m);
    ctx.stroke();
  }

  // ---- Controls --------------------------------------------------------------------------------
  const controls = renderer ? new THREE.OrbitControls(camera, renderer.domElement)
                            : { target: new THREE.Vector3(), update() {} };
  const center = extent.getCenter(new THREE.Vector3());
  {  // framed on the model: seen from a corner, a little above
    const side = new THREE.Vector3(1, 0, 0);
    if (Math.abs(side.dot(up)) > 0.9) side.set(0, 1, 0);
    const across = up.clone().cross(side).normalize();
    side.crossVectors(across, up).normalize();
    const dir = side.add(across.multiplyScalar(-1.2)).add(up.clone().multiplyScalar(0.8))
        .normalize();
    const radius = Math.max(0.5 * L, 0.03);
    const distance = 1.05 * radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2));
    camera.position.copy(center).addScaledVector(dir, distance);
    controls.target.copy(center);
    controls.update();
  }
  const playButton = document.getElementById('play');
  const slider = document.getElementById('time');
  const timeLabel = document.getElementById('time-label');
  document.getElementById('speed').addEventListener('change', (e) => {
    state.speed = +e.target.value;
  });
  document.getElementById('loop').addEventListener('change', (e) => {
    state.loop = e.target.checked;
  });
  playButton.disabled = slider.disabled = !(motion.trajectory && T.length > 1);
  playButton.addEventListener('click', () => {
    if (!state.playing && state.t >= t1) state.t = t0;
    state.playing = !state.playing;
  });
  slider.addEventListener('input', () => {
    state.playing = false;
    state.t = t0 + (t1 - t0) * slider.value / 1000;
  });
  function timeFromHash() {  // #t=SECONDS: that time, paused
    const m = /(?:^#|&)t=([-+0-9.eE]+)/.exec(window.location.hash);
    if (!m || !isFinite(+m[1])) return;
    state.t = Math.min(Math.max(+m[1], t0), t1);
    state.playing = false;
  }
  window.addEventListener('hashchange', timeFromHash);
  timeFromHash();

  // Hover: the name of what is under the pointer.
  const tooltip = document.getElementById('tooltip');
  const raycaster = new THREE.Raycaster();
  if (renderer) renderer.domElement.addEventListener('pointermove', (ev) => {
    const r = renderer.domElement.getBoundingClientRect();
    const pointer = new THREE.Vector2(((ev.clientX - r.left) / r.width) * 2 - 1,
                                      -((ev.clientY - r.top) / r.height) * 2 + 1);
    raycaster.setFromCamera(pointer, camera);
    const hit = raycaster.intersectObjects(pickable, false)[0];
    tooltip.style.display = hit ? 'block' : 'none';
    if (!hit) return;
    tooltip.textContent = hit.object.userData.label;
    tooltip.style.left = `${ev.clientX - r.left + 12}px`;
    tooltip.style.top = `${ev.clientY - r.top + 12}px`;
  });

  function resize() {
    const w = Math.max(container.clientWidth, 1), h = Math.max(container.clientHeight, 1);
    if (renderer) renderer.setSize(w, h);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }
  window.addEventListener('resize', resize);
  resize();

  // ---- The loop ------------------------------------------------------------------------------
  function show() {
    placeBodies(state.t);
    if (renderer) renderer.render(scene, camera);
    plots.forEach((p) => drawPlot(p, state.t));
    slider.value = t1 > t0 ? Math.round(1000 * (state.t - t0) / (t1 - t0)) : 0;
    timeLabel.textContent = `t = ${state.t.toFixed(3)} s`;
    playButton.textContent = state.playing ? 'Pause' : 'Play';
    statusBox.dataset.time = state.t;
  }
  let last = null;
  function tick(now) {
    if (state.playing && last !== null) {
      state.t += state.speed * (now - last) / 1000;
      if (state.t > t1) {
        if (state.loop) state.t = t0 + ((state.t - t0) % Math.max(t1 - t0, 1e-9));
        else { state.t = t1; state.playing = false; }
      }
    }
    last = now;
    controls.update();
    show();
    requestAnimationFrame(tick);
  }
  show();

  // Where each named object is on the screen (CSS pixels), for the hover test.
  window.femdynView = {
    // Each loop constraint's two places as drawn (world coordinates) and their distance.
    closures: () => closures.map((c) => {
      const [a, b] = c.ends.map((dot) => dot.getWorldPosition(new THREE.Vector3()));
      return { a: a.toArray(), b: b.toArray(), distance: a.distanceTo(b), extent: L };
    }),
    // Each flexible bar as drawn: its stations (world coordinates, from femdyn's poses) and
    // every tenth vertex of its tube.
    bars: () => bars.map((b) => {
      const position = b.mesh.geometry.getAttribute('position');
      const vertices = [];
      for (let i = 0; position && i < position.count; i += 10)
        vertices.push([position.getX(i), position.getY(i), position.getZ(i)]);
      return { radius: b.radius, vertices: vertices,
               stations: b.stations.map((s) => groups[s].getWorldPosition(new THREE.Vector3())
                                                         .toArray()) };
    }),
    // The share of each plot's pixels drawn (not blank), WebGL or not.
    plotInk: () => plots.map((plot) => {
      const c = plot.canvas, px = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let ink = 0;
      for (let i = 3; i < px.length; i += 4) ink += px[i] > 0;
      return ink / (px.length / 4);
    }),
    labelsOnScreen: () => (renderer ? pickable : []).filter((mesh) => mesh.visible).map((mesh) => {
      const at = mesh.userData.anchor ? mesh.userData.anchor()
                                      : mesh.getWorldPosition(new THREE.Vector3());
      const p = at.project(camera);
      const r = renderer.domElement.getBoundingClientRect();
      return { label: mesh.userData.label, x: r.left + (p.x + 1) / 2 * r.width,
               y: r.top + (1 - p.y) / 2 * r.height };
    }),
  };

  // What the page holds, for its reader and its tests (tests/view_browser.py).
  window.femdynScene = Object.assign({ motionFrames: T.length,
                                       webgl: !!(renderer && renderer.getContext()) }, counts);
  for (const [k, v] of Object.entries(window.femdynScene)) statusBox.dataset[k] = v;
  if (window.femdynErrors.length === 0) {
    statusBox.dataset.status = 'ok';
    statusBox.textContent = `femdyn view: ${counts.bodies} bodies, ${counts.elements} elements`;
  }
  requestAnimationFrame(tick);
})();

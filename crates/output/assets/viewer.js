// fbd viewer.html: draws the scene that `fbd run` / `fbd view` embedded as
// JSON (element #fbd-scene). Every point was computed by fbd's kinematics in
// Rust; this script only draws: three.js for the robot, 2D canvases for the
// time-series panels.
//
// For tests, window.fbdViewer exposes the frame count, the current frame,
// seek/play/pause, and the world and screen positions of the drawn points.
(function () {
  'use strict';
  const S = JSON.parse(document.getElementById('fbd-scene').textContent);
  const N = S.t.length;
  const planar = S.model === 'planar';
  // Every 3D model (an imported URDF/MJCF robot, the hexapod) is one kind
  // of scene: its bodies as capsules of radius S.radius between the points
  // (joint origins, contact points, points fixed in bodies, centres of
  // mass), one colour per limb; what a model adds is data of the scene
  // (S.plate, S.labels, S.heading, S.ring, S.joints, S.state_names).
  const robotKind = !planar;
  // Contact states ST1/ST2/ST3 and force arrows: the planar model and a
  // 3D run with contacts (a kinematic gait has only swing and stance:
  // S.state_names).
  const forces = planar || !!S.dynamic;
  const NP = S.points.length;

  // Colours: body, legs (planar: leg 3 blue, leg 4 red, as in the plots),
  // contact states, arrows.
  const BODY = 0x263238;
  const LEGS = planar
    ? [0x1f77b4, 0xd62728]
    : [0x1f77b4, 0xd62728, 0x2ca02c, 0x9467bd, 0xff7f0e, 0x8c564b];
  const STATE = { '1': 0x9e9e9e, '2': 0x2e7d32, '3': 0xe65100 };
  const STATE_NAME = { '1': 'ST1 no contact', '2': 'ST2 sticking', '3': 'ST3 sliding' };
  const CONTACT_FORCE = 0x00897b;
  const JOINT_FORCE = 0x8e24aa;
  const css = (c) => '#' + c.toString(16).padStart(6, '0');

  // ---- geometry of the run -------------------------------------------
  const bbox = { min: [Infinity, Infinity, Infinity], max: [-Infinity, -Infinity, -Infinity] };
  for (const p of S.p) {
    for (let i = 0; i < p.length; i += 3) {
      for (let k = 0; k < 3; k++) {
        bbox.min[k] = Math.min(bbox.min[k], p[i + k]);
        bbox.max[k] = Math.max(bbox.max[k], p[i + k]);
      }
    }
  }
  if (!(bbox.min[0] <= bbox.max[0])) { bbox.min = [-1, -1, -1]; bbox.max = [1, 1, 1]; }
  const size = Math.max(bbox.max[0] - bbox.min[0], bbox.max[1] - bbox.min[1], bbox.max[2] - bbox.min[2], 0.3);
  // Robot size: extent of the first frame.
  let robot = 0.3;
  if (N > 0) {
    const p = S.p[0];
    let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < p.length; i += 3) for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[i + k]); hi[k] = Math.max(hi[k], p[i + k]); }
    robot = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 0.1);
  }
  // Force arrows: the 90th percentile of the contact forces' magnitudes is
  // 0.3 (side view) or 0.4 (3D) of the robot's size (impact peaks would
  // make the rest invisible); longer arrows are clipped (MAX_ARROW).
  const mags = [];
  for (const f of S.fc) for (let i = 0; i < f.length; i += 3) { const m = Math.hypot(f[i], f[i + 1], f[i + 2]); if (m > 0) mags.push(m); }
  mags.sort((a, b) => a - b);
  const fref = mags.length ? mags[Math.floor(0.9 * (mags.length - 1))] : 0;
  const forceScale = fref > 0 ? (planar ? 0.3 : 0.4) * robot / fref : 0; // m per N
  // Longest arrow (m): an impact's force is clipped to it, so that the
  // arrow stays in the view, and its magnitude written beside the view.
  const MAX_ARROW = (planar ? 0.45 : 0.6) * robot;
  const radius = robotKind && S.radius > 0 ? S.radius : (planar ? 0.022 : 0.012) * robot;

  // ---- three.js scene ------------------------------------------------
  const canvas = document.getElementById('canvas3d');
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    const view = document.getElementById('view');
    const msg = document.createElement('div');
    msg.id = 'error';
    msg.textContent = 'This browser cannot draw WebGL: ' + e.message;
    view.replaceChildren(msg);
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0xffffff);
  const scene = new THREE.Scene();
  scene.add(new THREE.AmbientLight(0xffffff, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(1, 3, 2);
  scene.add(sun);

  const mat = (c, opts) => new THREE.MeshLambertMaterial(Object.assign({ color: c }, opts || {}));
  const sphereGeo = new THREE.SphereGeometry(1, 16, 12);
  const cylGeo = new THREE.CylinderGeometry(1, 1, 1, 12);
  const Y = new THREE.Vector3(0, 1, 0);

  function setCylinder(mesh, a, b, r) {
    const d = new THREE.Vector3().subVectors(b, a);
    const len = d.length();
    mesh.position.copy(a).addScaledVector(d, 0.5);
    if (len > 1e-12) mesh.quaternion.setFromUnitVectors(Y, d.divideScalar(len));
    mesh.scale.set(r, Math.max(len, 1e-9), r);
  }

  // Links; a robot's are capsules: a cylinder and a sphere at each end.
  const links = S.lines.map((l) => {
    const c = l.group === 0 ? BODY : LEGS[(l.group - 1) % LEGS.length];
    const material = mat(c);
    const m = new THREE.Mesh(cylGeo, material);
    m.userData = { line: l, r: l.group === 0 && planar ? 1.6 * radius : radius, caps: [] };
    if (robotKind) {
      for (let k = 0; k < 2; k++) {
        const cap = new THREE.Mesh(sphereGeo, material);
        cap.scale.setScalar(radius);
        scene.add(cap);
        m.userData.caps.push(cap);
      }
    }
    scene.add(m);
    return m;
  });
  // Joints and points (small spheres), contact points coloured by state.
  const contactOf = new Map(S.contacts.map((c, i) => [c.point, i]));
  const dots = S.points.map((name, i) => {
    const isContact = contactOf.has(i);
    const isCom = planar ? /com/.test(name) : robotKind && /_com$/.test(name);
    const m = new THREE.Mesh(sphereGeo, mat(isContact ? STATE['1'] : isCom ? 0x607d8b : BODY));
    const r = isContact ? 1.5 * radius : isCom ? 0.9 * radius : robotKind ? 1.2 * radius : 1.3 * radius;
    m.scale.setScalar(r);
    scene.add(m);
    return m;
  });
  // The root's outline (S.plate, point indices in order: a hexapod's body
  // hexagon, a robot's ring of hips) filled with a translucent plate
  // fanned from `base` (point 0).
  let plate = null;
  if (robotKind && S.plate && S.plate.length >= 3) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(S.plate.length * 9), 3));
    plate = new THREE.Mesh(g, new THREE.MeshBasicMaterial({ color: 0x90a4ae, transparent: true, opacity: 0.55, side: THREE.DoubleSide }));
    scene.add(plate);
  }
  // Centre of mass and its vertical line to the ground.
  const com = new THREE.Mesh(sphereGeo, mat(0x000000));
  com.scale.setScalar(1.5 * radius);
  scene.add(com);
  const comLine = new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3()]),
    new THREE.LineDashedMaterial({ color: 0x000000, dashSize: 0.02, gapSize: 0.015 }));
  scene.add(comLine);
  // Support polygon of the stance feet (S.ring: a hexapod's feet).
  const support = new THREE.LineLoop(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0x2e7d32 }));
  support.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * Math.max(S.ring.length, 1)), 3));
  scene.add(support);
  // Force arrows.
  // Drawn over the robot (no depth test) so that short arrows stay visible.
  const arrow = (c) => {
    const a = new THREE.ArrowHelper(Y, new THREE.Vector3(), 0.1, c);
    for (const part of [a.line, a.cone]) { part.material.depthTest = false; part.renderOrder = 10; }
    scene.add(a);
    return a;
  };
  const contactArrows = S.contacts.map(() => arrow(CONTACT_FORCE));
  const jointArrows = S.joints.map(() => arrow(JOINT_FORCE));
  // Trails of the feet.
  const trails = S.trails.map((pi, k) => {
    const pos = new Float32Array(3 * Math.max(N, 1));
    for (let f = 0; f < N; f++) for (let a = 0; a < 3; a++) pos[3 * f + a] = S.p[f][3 * pi + a];
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    // 3D: the colour of the limb whose capsule ends at the trail's point.
    const leg = S.lines.find((l) => l.b === pi && l.group > 0);
    const c = planar || !leg ? LEGS[k % LEGS.length] : LEGS[(leg.group - 1) % LEGS.length];
    const line = new THREE.Line(g, new THREE.LineBasicMaterial({ color: c, transparent: true, opacity: 0.6 }));
    scene.add(line);
    return line;
  });
  // Terrain: the heights y = ϱ(x, z) on a grid (3D), or the profile
  // y = ϱ(x), drawn as a line with a shaded area below (planar) or extruded
  // along Z.
  if (S.terrain.kind === 'grid') {
    const { x0, x1, z0, z1, n, y } = S.terrain;
    const pos = [], idx = [];
    for (let j = 0; j < n; j++) {
      for (let i = 0; i < n; i++) pos.push(x0 + (x1 - x0) * i / (n - 1), y[j * n + i], z0 + (z1 - z0) * j / (n - 1));
    }
    for (let j = 0; j + 1 < n; j++) {
      for (let i = 0; i + 1 < n; i++) {
        const a = j * n + i;
        idx.push(a, a + n, a + 1, a + 1, a + n, a + n + 1);
      }
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    g.setIndex(idx);
    g.computeVertexNormals();
    scene.add(new THREE.Mesh(g, new THREE.MeshLambertMaterial({ color: 0xe8e0d0, side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 })));
    // Grid lines every 5 samples, to see the slope and the motion.
    const lines = [];
    for (let k = 0; k < n; k += 5) {
      for (let m = 0; m + 1 < n; m++) {
        lines.push(pos[3 * (k * n + m)], pos[3 * (k * n + m) + 1], pos[3 * (k * n + m) + 2], pos[3 * (k * n + m + 1)], pos[3 * (k * n + m + 1) + 1], pos[3 * (k * n + m + 1) + 2]);
        lines.push(pos[3 * (m * n + k)], pos[3 * (m * n + k) + 1], pos[3 * (m * n + k) + 2], pos[3 * ((m + 1) * n + k)], pos[3 * ((m + 1) * n + k) + 1], pos[3 * ((m + 1) * n + k) + 2]);
      }
    }
    const lg = new THREE.BufferGeometry();
    lg.setAttribute('position', new THREE.Float32BufferAttribute(lines, 3));
    scene.add(new THREE.LineSegments(lg, new THREE.LineBasicMaterial({ color: 0xc8bca8 })));
    drawPatches(scene, S, 0.002);
  } else if (S.terrain.kind === 'profile' && S.terrain.xy.length >= 4) {
    const xy = S.terrain.xy;
    const m = xy.length / 2;
    const depth = planar ? 0 : Math.max(2 * size, 2);
    const zc = planar ? 0 : 0.5 * (bbox.min[2] + bbox.max[2]);
    const below = Math.min(bbox.min[1], ...xy.filter((_, i) => i % 2 === 1)) - 0.5 * size - 0.2;
    const pos = [], idx = [];
    for (let i = 0; i < m; i++) {
      const x = xy[2 * i], y = xy[2 * i + 1];
      if (planar) pos.push(x, y, -0.01, x, below, -0.01);
      else pos.push(x, y, zc - depth, x, y, zc + depth);
      if (i > 0) { const a = 2 * (i - 1); idx.push(a, a + 1, a + 2, a + 1, a + 3, a + 2); }
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    g.setIndex(idx);
    g.computeVertexNormals();
    scene.add(new THREE.Mesh(g, new THREE.MeshBasicMaterial({ color: planar ? 0xefe6d8 : 0xe8e0d0, side: THREE.DoubleSide })));
    const edge = [];
    for (let i = 0; i < m; i++) edge.push(new THREE.Vector3(xy[2 * i], xy[2 * i + 1], planar ? 0 : zc));
    scene.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(edge), new THREE.LineBasicMaterial({ color: 0x78552d })));
    if (!planar) {
      // A few lines across the ground to see its slope and the motion.
      const step = Math.max(0.1, Math.pow(10, Math.floor(Math.log10(size))) / 2);
      for (let i = 0; i < m; i += Math.max(1, Math.round(m / 80))) {
        const x = xy[2 * i], y = xy[2 * i + 1] + 1e-4;
        if (Math.abs(x / step - Math.round(x / step)) > 0.5 * (xy[2] - xy[0]) / step) continue;
        scene.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(x, y, zc - depth), new THREE.Vector3(x, y, zc + depth)]),
          new THREE.LineBasicMaterial({ color: 0xc8bca8 })));
      }
    }
  }

  // ---- camera --------------------------------------------------------
  let camera;
  const view = { target: new THREE.Vector3(), dist: 2.1 * Math.max(robot, 0.3), yaw: -0.6, pitch: 0.35, zoom: 1, pan: new THREE.Vector3() };
  if (planar) {
    camera = new THREE.OrthographicCamera(-1, 1, 1, -1, -100, 100);
    camera.position.set(0, 0, 10);
  } else {
    camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
  }
  const follow = document.getElementById('follow');
  function placeCamera() {
    const w = canvas.clientWidth || 800, h = canvas.clientHeight || 450;
    renderer.setSize(w, h, false);
    const centre = new THREE.Vector3();
    if (follow.checked && N > 0) centre.set(S.com[frame][0], S.com[frame][1], S.com[frame][2]);
    else centre.set(0.5 * (bbox.min[0] + bbox.max[0]), 0.5 * (bbox.min[1] + bbox.max[1]), 0.5 * (bbox.min[2] + bbox.max[2]));
    centre.add(view.pan);
    if (planar) {
      // Side view of the XY plane, equal scales; the robot's size (or the
      // whole run, when not following) fills the height.
      const span = follow.checked ? 1.3 * robot : 1.15 * Math.max(bbox.max[0] - bbox.min[0], (bbox.max[1] - bbox.min[1]) * w / h, robot) * h / w;
      const half = 0.5 * Math.max(span, 0.2) / view.zoom;
      camera.left = centre.x - half * w / h; camera.right = centre.x + half * w / h;
      camera.top = centre.y + half; camera.bottom = centre.y - half;
      camera.updateProjectionMatrix();
    } else {
      const d = view.dist / view.zoom;
      camera.aspect = w / h;
      camera.position.set(centre.x + d * Math.cos(view.pitch) * Math.sin(view.yaw), centre.y + d * Math.sin(view.pitch), centre.z + d * Math.cos(view.pitch) * Math.cos(view.yaw));
      camera.lookAt(centre);
      camera.updateProjectionMatrix();
    }
    camera.updateMatrixWorld();
  }
  // Mouse: drag orbits (3D) or pans (side view), the wheel zooms.
  let drag = null;
  canvas.addEventListener('pointerdown', (e) => { drag = { x: e.clientX, y: e.clientY }; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag = { x: e.clientX, y: e.clientY };
    if (planar) {
      const perPx = (camera.top - camera.bottom) / (canvas.clientHeight || 1);
      view.pan.x -= dx * perPx; view.pan.y += dy * perPx;
    } else {
      view.yaw -= 0.01 * dx;
      view.pitch = Math.max(-1.4, Math.min(1.4, view.pitch + 0.01 * dy));
    }
    draw();
  });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    view.zoom = Math.max(0.1, Math.min(50, view.zoom * Math.exp(-0.001 * e.deltaY)));
    draw();
  }, { passive: false });

  // ---- per-frame update ------------------------------------------------
  let frame = 0;
  const showContact = document.getElementById('show-contact');
  const showJoint = document.getElementById('show-joint');
  const showTrails = document.getElementById('show-trails');
  const P = (f, i) => new THREE.Vector3(S.p[f][3 * i], S.p[f][3 * i + 1], S.p[f][3 * i + 2]);

  // The arrows clipped at the frame drawn: [name, magnitude (N)].
  let clipped = [];
  function setArrow(a, at, f, k, visible, name) {
    const v = new THREE.Vector3(f[3 * k], f[3 * k + 1], f[3 * k + 2]);
    const full = v.length() * forceScale;
    const len = Math.min(full, MAX_ARROW);
    a.visible = visible && len > 1e-4;
    if (!a.visible) return;
    if (full > MAX_ARROW) clipped.push([name, v.length()]);
    a.position.copy(at);
    a.setDirection(v.normalize());
    a.setLength(len, Math.min(0.25 * len, 0.06 * robot), Math.min(0.15 * len, 0.035 * robot));
  }

  function update() {
    if (N === 0) return;
    const f = frame;
    for (const m of links) {
      const a = P(f, m.userData.line.a), b = P(f, m.userData.line.b);
      setCylinder(m, a, b, m.userData.r);
      if (m.userData.caps.length) { m.userData.caps[0].position.copy(a); m.userData.caps[1].position.copy(b); }
    }
    dots.forEach((m, i) => m.position.copy(P(f, i)));
    const st = S.state[f];
    clipped = [];
    S.contacts.forEach((c, k) => {
      dots[c.point].material.color.setHex(STATE[st[k]] || STATE['1']);
      setArrow(contactArrows[k], P(f, c.point), S.fc[f], k, showContact.checked, c.name);
    });
    S.joints.forEach((j, k) => setArrow(jointArrows[k], P(f, j.point), S.fj[f], k, showJoint.checked, j.name + ' joint'));
    updateLabels(f);
    if (plate) {
      const a = plate.geometry.attributes.position;
      const cs = S.plate;
      const c0 = P(f, 0);
      cs.forEach((ci, k) => {
        const p1 = P(f, ci), p2 = P(f, cs[(k + 1) % cs.length]);
        a.setXYZ(3 * k, c0.x, c0.y, c0.z); a.setXYZ(3 * k + 1, p1.x, p1.y, p1.z); a.setXYZ(3 * k + 2, p2.x, p2.y, p2.z);
      });
      a.needsUpdate = true;
      plate.geometry.computeBoundingSphere();
    }
    const c = new THREE.Vector3(S.com[f][0], S.com[f][1], S.com[f][2]);
    com.position.copy(c);
    const ground = groundBelow(c.x, c.z);
    comLine.geometry.setFromPoints([c, new THREE.Vector3(c.x, ground, c.z)]);
    comLine.computeLineDistances();
    // Support polygon: the stance feet in their order around the body.
    const feet = S.ring.filter((k) => st[k] !== '1');
    const sp = support.geometry.attributes.position;
    feet.forEach((k, i) => { const p = P(f, S.contacts[k].point); sp.setXYZ(i, p.x, p.y + 1e-3, p.z); });
    sp.needsUpdate = true;
    support.geometry.setDrawRange(0, feet.length >= 2 ? feet.length : 0);
    support.geometry.computeBoundingSphere();
    for (const t of trails) { t.visible = showTrails.checked; t.geometry.setDrawRange(0, f + 1); }
  }

  function groundBelow(x, z) {
    if (S.terrain.kind === 'grid') {
      const { x0, x1, z0, z1, n, y } = S.terrain;
      const i = Math.max(0, Math.min(n - 1, Math.round((x - x0) / (x1 - x0) * (n - 1))));
      const j = Math.max(0, Math.min(n - 1, Math.round((z - z0) / (z1 - z0) * (n - 1))));
      return y[j * n + i];
    }
    const xy = S.terrain.xy;
    if (!xy || xy.length < 4) return bbox.min[1];
    for (let i = 2; i < xy.length; i += 2) {
      if (xy[i] >= x) {
        const x0 = xy[i - 2], y0 = xy[i - 1], x1 = xy[i], y1 = xy[i + 1];
        return x1 > x0 ? y0 + (y1 - y0) * (x - x0) / (x1 - x0) : y0;
      }
    }
    return xy[xy.length - 1];
  }

  // ---- labels (a hexapod's leg numbers) and the heading arrow -------------
  // A label beside each of S.labels' points (sprites that face the camera,
  // in the colour of their group), and an arrow from `base` (point 0)
  // towards S.heading (a hexapod's front vertex, corner2).
  const legLabels = [];
  let headingArrow = null;
  for (const l of (robotKind && S.labels) || []) {
    const c = document.createElement('canvas');
    c.width = c.height = 64;
    const g = c.getContext('2d');
    g.fillStyle = '#ffffff'; g.beginPath(); g.arc(32, 32, 28, 0, 2 * Math.PI); g.fill();
    g.strokeStyle = css(l.group > 0 ? LEGS[(l.group - 1) % LEGS.length] : BODY); g.lineWidth = 6; g.stroke();
    g.fillStyle = '#263238'; g.font = 'bold ' + (l.text.length > 2 ? 24 : 40) + 'px sans-serif'; g.textAlign = 'center'; g.textBaseline = 'middle';
    g.fillText(l.text, 32, 34);
    const sp = new THREE.Sprite(new THREE.SpriteMaterial({ map: new THREE.CanvasTexture(c), depthTest: false }));
    sp.renderOrder = 11;
    sp.scale.setScalar(0.07 * robot);
    scene.add(sp);
    legLabels.push({ text: l.text, point: l.point, sprite: sp });
  }
  if (robotKind && typeof S.heading === 'number') {
    headingArrow = new THREE.ArrowHelper(Y, new THREE.Vector3(), 0.1, 0xff6f00);
    for (const part of [headingArrow.line, headingArrow.cone]) { part.material.depthTest = false; part.renderOrder = 10; }
    scene.add(headingArrow);
  }
  function updateLabels(f) {
    // A third of the way from the point to `base`, above it: clear of a
    // hexapod's body corners and knees.
    const b = P(f, 0);
    for (const l of legLabels) {
      const p = P(f, l.point).lerp(b, 0.3);
      l.sprite.position.set(p.x, p.y + 0.1 * robot, p.z);
    }
    if (headingArrow) {
      const d = P(f, S.heading).sub(b);
      headingArrow.position.copy(b);
      headingArrow.setDirection(d.normalize());
      headingArrow.setLength(0.45 * robot, 0.08 * robot, 0.04 * robot);
    }
  }

  // ---- overlay: scale bar and axes (side view), slope, clipped arrows --------
  const overlay = document.getElementById('overlay');
  // The terrain's slope when its profile is one straight line (°).
  let slopeNote = '';
  const riseNote = (deg, dir) => 'ground: ' + deg.toFixed(1) + '° slope, rising towards ' + dir;
  if (S.terrain.kind === 'grid' && S.terrain.n >= 2) {
    // A plane y = y00 + gx·(x − x0) + gz·(z − z0) through three corners,
    // when every sample lies on it.
    const { x0, x1, z0, z1, n, y } = S.terrain;
    const gx = (y[n - 1] - y[0]) / (x1 - x0), gz = (y[(n - 1) * n] - y[0]) / (z1 - z0);
    let plane = true;
    for (let j = 0; j < n && plane; j++) {
      for (let i = 0; i < n; i++) {
        const want = y[0] + gx * (x1 - x0) * i / (n - 1) + gz * (z1 - z0) * j / (n - 1);
        if (Math.abs(want - y[j * n + i]) > 1e-5) { plane = false; break; }
      }
    }
    const g = Math.hypot(gx, gz);
    if (plane && g > 1e-9) {
      const dir = Math.abs(gx) >= Math.abs(gz) ? (gx > 0 ? '+X' : '−X') : (gz > 0 ? '+Z' : '−Z');
      slopeNote = riseNote(Math.atan(g) * 180 / Math.PI, Math.abs(gx) > 1e-9 && Math.abs(gz) > 1e-9 ? dir + ' (mostly)' : dir);
    }
  } else if (S.terrain.kind === 'profile' && S.terrain.xy.length >= 4) {
    const xy = S.terrain.xy, m = xy.length / 2;
    const k = (xy[2 * m - 1] - xy[1]) / (xy[2 * m - 2] - xy[0]);
    let straight = true;
    for (let i = 1; i < m - 1; i++) if (Math.abs(xy[1] + k * (xy[2 * i] - xy[0]) - xy[2 * i + 1]) > 1e-6) straight = false;
    if (straight && Math.abs(k) > 1e-9) {
      slopeNote = riseNote(Math.atan(Math.abs(k)) * 180 / Math.PI, k > 0 ? '+X' : '−X');
    }
  }
  let scaleBar = { metres: 0, px: 0 };
  function drawOverlay() {
    const parts = [];
    if (planar) {
      const perM = (canvas.clientHeight || 1) / (camera.top - camera.bottom);
      const want = 110 / perM;
      const e = Math.pow(10, Math.floor(Math.log10(want)));
      const metres = [5, 2, 1].map((x) => x * e).find((x) => x <= want) || e;
      scaleBar = { metres, px: metres * perM };
      parts.push('<span class="bar" style="width:' + scaleBar.px.toFixed(1) + 'px"></span> ' +
        Number(metres.toPrecision(2)) + ' m', '<span class="axes">↑ Y (up) → X</span>');
    } else {
      parts.push('<span class="axes">axes: <b style="color:#e53935">X</b> <b style="color:#43a047">Y up</b> <b style="color:#1e88e5">Z</b>' + (headingArrow ? '; <b style="color:#ff6f00">→</b> heading' : '') + '</span>');
    }
    if (slopeNote) parts.push(slopeNote);
    if (clipped.length) {
      parts.push('<span class="clip">arrows clipped at ' + Number(MAX_ARROW.toPrecision(2)) + ' m: ' +
        clipped.map(([n, v]) => n + ' ' + v.toFixed(0) + ' N').join(', ') + '</span>');
    }
    overlay.innerHTML = parts.join('<br>');
  }
  if (!planar) {
    // Inertial axes at the ground below the first frame's body.
    const axes = new THREE.AxesHelper(0.35 * robot);
    const c0 = N ? S.com[0] : [0, 0, 0];
    axes.position.set(c0[0], groundBelow(c0[0], c0[2]) + 1e-3, c0[2]);
    scene.add(axes);
  }

  // ---- controls --------------------------------------------------------
  const slider = document.getElementById('slider');
  const timeLabel = document.getElementById('time');
  const playButton = document.getElementById('play');
  const speed = document.getElementById('speed');
  slider.max = String(Math.max(N - 1, 0));
  let playing = false, simTime = 0, lastWall = 0;

  function draw() {
    placeCamera();
    update();
    renderer.render(scene, camera);
    drawOverlay();
    slider.value = String(frame);
    timeLabel.textContent = N ? 't = ' + S.t[frame].toFixed(4) + ' s  (' + (frame + 1) + '/' + N + ')' : 'no frames';
    drawPanels();
  }
  function seek(i) {
    frame = Math.max(0, Math.min(N - 1, Math.round(i)));
    simTime = N ? S.t[frame] : 0;
    draw();
  }
  function tick(now) {
    if (!playing) return;
    simTime += Math.min(0.25, (now - lastWall) / 1000) * Number(speed.value);
    lastWall = now;
    while (frame + 1 < N && S.t[frame + 1] <= simTime) frame++;
    draw();
    if (frame + 1 >= N) { pause(); return; }
    requestAnimationFrame(tick);
  }
  function play() {
    if (playing || N < 2) return;
    if (frame + 1 >= N) frame = 0;
    simTime = S.t[frame];
    playing = true;
    playButton.textContent = '❚❚ pause';
    lastWall = performance.now();
    requestAnimationFrame(tick);
  }
  function pause() {
    playing = false;
    playButton.textContent = '▶ play';
  }
  playButton.addEventListener('click', () => (playing ? pause() : play()));
  document.getElementById('step').addEventListener('click', () => { pause(); seek(frame + 1); });
  document.getElementById('step-back').addEventListener('click', () => { pause(); seek(frame - 1); });
  slider.addEventListener('input', () => { pause(); seek(Number(slider.value)); });
  for (const el of [showContact, showJoint, showTrails, follow]) el.addEventListener('change', draw);
  document.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'SELECT') return;
    if (e.key === ' ') { e.preventDefault(); playing ? pause() : play(); }
    else if (e.key === 'ArrowRight') { pause(); seek(frame + 1); }
    else if (e.key === 'ArrowLeft') { pause(); seek(frame - 1); }
  });
  window.addEventListener('resize', draw);

  // ---- time-series panels ------------------------------------------------
  const PALETTE = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b', '#17becf', '#e377c2', '#7f7f7f', '#bcbd22'];
  const DASHES = [[], [7, 4], [2, 3]];
  const DASH_KEY = ['— ', '╌ ', '┈ '];
  const panels = S.panels.filter((p) => p.curves.length > 0).map((p) => {
    const div = document.createElement('div');
    div.className = 'panel';
    const h = document.createElement('h2');
    h.textContent = p.title;
    const keys = document.createElement('div');
    keys.className = 'keys';
    p.curves.forEach((c, i) => {
      const s = document.createElement('span');
      s.style.color = PALETTE[i % PALETTE.length];
      s.textContent = DASH_KEY[i % DASHES.length] + c.label;
      keys.appendChild(s);
    });
    const cv = document.createElement('canvas');
    div.append(h, keys, cv);
    document.getElementById('panels').appendChild(div);
    let lo = Infinity, hi = -Infinity;
    for (const c of p.curves) for (const v of c.v) if (v !== null) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (!(lo <= hi)) { lo = 0; hi = 1; }
    if (hi - lo < 1e-9) { lo -= 0.5; hi += 0.5; }
    const pad = 0.06 * (hi - lo);
    const panel = { p, cv, lo: lo - pad, hi: hi + pad };
    cv.addEventListener('click', (e) => {
      const r = cv.getBoundingClientRect();
      const t = panel.t0 + (e.clientX - r.left - panel.left) / panel.w * (panel.t1 - panel.t0);
      let best = 0;
      for (let i = 0; i < N; i++) if (Math.abs(S.t[i] - t) < Math.abs(S.t[best] - t)) best = i;
      pause();
      seek(best);
    });
    return panel;
  });

  function drawPanels() {
    for (const pn of panels) {
      const cv = pn.cv;
      const dpr = window.devicePixelRatio || 1;
      const w = cv.clientWidth || 400, h = cv.clientHeight || 130;
      if (cv.width !== Math.round(w * dpr)) { cv.width = Math.round(w * dpr); cv.height = Math.round(h * dpr); pn.cache = null; }
      const g = cv.getContext('2d');
      g.setTransform(dpr, 0, 0, dpr, 0, 0);
      pn.left = 52; pn.w = w - pn.left - 8;
      pn.t0 = N ? S.t[0] : 0; pn.t1 = N > 1 ? S.t[N - 1] : pn.t0 + 1;
      const top = 6, ph = h - top - 20;
      const X = (t) => pn.left + (t - pn.t0) / (pn.t1 - pn.t0) * pn.w;
      const Yv = (v) => top + (pn.hi - v) / (pn.hi - pn.lo) * ph;
      if (!pn.cache) {
        g.clearRect(0, 0, w, h);
        g.font = '10px sans-serif';
        g.fillStyle = '#555';
        g.strokeStyle = '#ccc';
        g.lineWidth = 1;
        g.strokeRect(pn.left, top, pn.w, ph);
        for (const v of [pn.lo, 0.5 * (pn.lo + pn.hi), pn.hi]) g.fillText(Number(v.toPrecision(3)).toString(), 2, Yv(v) + 3);
        g.fillText(pn.t0.toFixed(2) + ' s', pn.left, h - 6);
        const endLabel = pn.t1.toFixed(2) + ' s';
        g.fillText(endLabel, pn.left + pn.w - g.measureText(endLabel).width, h - 6);
        if (pn.lo < 0 && pn.hi > 0) { g.strokeStyle = '#eee'; g.beginPath(); g.moveTo(pn.left, Yv(0)); g.lineTo(pn.left + pn.w, Yv(0)); g.stroke(); }
        g.strokeStyle = '#bbb';
        g.setLineDash([3, 3]);
        for (const ev of S.events) { g.beginPath(); g.moveTo(X(ev.t), top); g.lineTo(X(ev.t), top + ph); g.stroke(); }
        pn.p.curves.forEach((c, i) => {
          g.strokeStyle = PALETTE[i % PALETTE.length];
          g.setLineDash(DASHES[i % DASHES.length]);
          g.lineWidth = 1.5;
          g.beginPath();
          let pen = false;
          for (let k = 0; k < N; k++) {
            const v = c.v[k];
            if (v === null) { pen = false; continue; }
            if (pen) g.lineTo(X(S.t[k]), Yv(v)); else g.moveTo(X(S.t[k]), Yv(v));
            pen = true;
          }
          g.stroke();
        });
        g.setLineDash([]);
        pn.cache = g.getImageData(0, 0, cv.width, cv.height);
      } else {
        g.putImageData(pn.cache, 0, 0);
      }
      if (N) {
        g.strokeStyle = '#e53935';
        g.lineWidth = 1.5;
        g.beginPath();
        g.moveTo(X(S.t[frame]), top);
        g.lineTo(X(S.t[frame]), top + ph);
        g.stroke();
      }
    }
  }

  // ---- header and legend -------------------------------------------------
  document.getElementById('title').textContent = 'fbd viewer — ' + S.title;
  const kindNote = planar ? 'planar model, side view'
    : (S.dynamic ? '3D dynamics on the ground' : S.state_names ? '3D kinematics' : '3D') + ' · capsules ' + Number((1000 * radius).toPrecision(2)) + ' mm';
  document.getElementById('info').textContent = kindNote + ' · ' + N + ' frames of ' + S.rows + ' rows' +
    (N < S.rows ? ' (decimated, every event kept)' : '') + ' · ' + (S.event_rows || S.events.length) + ' events (events.csv' +
    (S.event_rows > S.events.length ? '; ' + S.events.length + ' contact changes marked' : '') + ')' +
    (forceScale > 0 ? ' · arrows: ' + Number((0.1 / forceScale).toPrecision(2)) + ' N per 0.1 m' : '');
  const legend = document.getElementById('legend');
  // The contact states: named by the scene (a kinematic gait: swing,
  // stance), else ST1–ST3 (ST1 only without forces).
  const states = S.state_names ? S.state_names.map((name, i) => [String(i + 1), name])
    : (forces ? ['1', '2', '3'] : ['1']).map((s) => [s, STATE_NAME[s]]);
  for (const [s, name] of states) {
    const sw = document.createElement('span');
    sw.className = 'sw';
    sw.style.background = css(STATE[s] || STATE['1']);
    legend.append(sw, document.createTextNode(name));
  }
  const keys = planar
    ? [[CONTACT_FORCE, 'contact force'], [JOINT_FORCE, 'joint force'], [0x000000, 'centre of mass']]
    : (forces && S.contacts.length ? [[CONTACT_FORCE, 'ground force on the contact points']] : [])
      .concat(S.joints.length ? [[JOINT_FORCE, 'joint forces (parent on child): ' + S.joints.map((j) => j.name.replace(/\d+$/, '')).filter((n, i, a) => a.indexOf(n) === i).join(', ')]] : [])
      .concat([[BODY, 'root body'], [0x000000, 'centre of mass']])
      .concat(S.ring.length ? [[0x2e7d32, 'support polygon']] : []);
  for (const [c, label] of keys) {
    const sw = document.createElement('span');
    sw.className = 'sw';
    sw.style.background = css(c);
    legend.append(sw, document.createTextNode(label));
  }
  if (!forces) { showJoint.parentElement.style.display = 'none'; showContact.parentElement.style.display = 'none'; }
  if (S.joints.length === 0) showJoint.parentElement.style.display = 'none';

  // ---- the test interface -------------------------------------------------
  function worldPoints() {
    if (!N) return [];
    return S.points.map((name, i) => ({ name, x: S.p[frame][3 * i], y: S.p[frame][3 * i + 1], z: S.p[frame][3 * i + 2] }));
  }
  function screenPoints() {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    // The camera's up direction: a drawn sphere's radius on screen.
    const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
    return worldPoints().map((p, i) => {
      const c = new THREE.Vector3(p.x, p.y, p.z);
      const v = c.clone().project(camera);
      const e = c.addScaledVector(up, dots[i].scale.x).project(camera);
      return { name: p.name, x: (v.x + 1) / 2 * w, y: (1 - v.y) / 2 * h, depth: v.z, r: Math.hypot((e.x - v.x) / 2 * w, (e.y - v.y) / 2 * h) };
    });
  }
  window.fbdViewer = {
    frameCount: N,
    rows: S.rows,
    row: S.row,
    times: S.t,
    events: S.events,
    get frame() { return frame; },
    get playing() { return playing; },
    seek, play, pause, worldPoints, screenPoints,
    state() { return N ? S.state[frame] : ''; },
    dynamic: !!S.dynamic,
    model: S.model,
    radius,
    lines: S.lines,
    contactNames: S.contacts.map((c) => c.name),
    /** Capsules of a robot: [start, end] world points of each, drawn. */
    capsules() {
      return links.map((m) => [m.userData.line.a, m.userData.line.b].map((i) => {
        const p = P(frame, i);
        return [p.x, p.y, p.z];
      }));
    },
    contactForces() { return N ? S.fc[frame].slice() : []; },
    arrowsShown() { return contactArrows.filter((a) => a.visible).length; },
    /** Screen positions of the visible arrows' tips (contact and joint). */
    arrowTips() {
      const w = canvas.clientWidth, h = canvas.clientHeight;
      return contactArrows.concat(jointArrows).filter((a) => a.visible).map((a) => {
        a.updateMatrixWorld(true);
        const v = new THREE.Vector3(0, 1, 0).applyMatrix4(a.cone.matrixWorld).project(camera);
        return { x: (v.x + 1) / 2 * w, y: (1 - v.y) / 2 * h };
      });
    },
    clipped() { return clipped.slice(); },
    /** Shows or hides the leg numbers and the heading arrow (redraws). */
    annotations(on) {
      for (const l of legLabels) l.sprite.visible = on;
      if (headingArrow) headingArrow.visible = on;
      renderer.render(scene, camera);
    },
    scaleBar() { return Object.assign({}, scaleBar); },
    slopeNote,
    /** Labels (a hexapod's leg numbers): text, the point's name and the
     *  label's screen position. */
    legLabels() {
      const w = canvas.clientWidth, h = canvas.clientHeight;
      return legLabels.map((l) => {
        const v = l.sprite.position.clone().project(camera);
        return { text: l.text, point: S.points[l.point], x: (v.x + 1) / 2 * w, y: (1 - v.y) / 2 * h, visible: l.sprite.visible };
      });
    },
    /** The heading arrow's direction (world), or null. */
    heading() { return headingArrow && headingArrow.visible ? (() => { const d = new THREE.Vector3(0, 1, 0).applyQuaternion(headingArrow.quaternion); return [d.x, d.y, d.z]; })() : null; },
  };
  seek(0);
})();

// Friction patches [x0, x1, z0, z1, μS, μD] as translucent rectangles
// draped `lift` m above a grid terrain (bluer the more slippery), each
// labelled with its μS in the page's title of the mesh.
function drawPatches(scene, S, lift) {
  const T = S.terrain;
  if (!S.patches || T.kind !== 'grid') return;
  const { x0, x1, z0, z1, n, y } = T;
  const h = (x, z) => {
    const u = Math.max(0, Math.min(n - 1, (x - x0) / (x1 - x0) * (n - 1)));
    const v = Math.max(0, Math.min(n - 1, (z - z0) / (z1 - z0) * (n - 1)));
    const i = Math.min(n - 2, Math.floor(u)), j = Math.min(n - 2, Math.floor(v));
    const a = u - i, b = v - j;
    return (1 - a) * (1 - b) * y[j * n + i] + a * (1 - b) * y[j * n + i + 1]
      + (1 - a) * b * y[(j + 1) * n + i] + a * b * y[(j + 1) * n + i + 1];
  };
  for (const [px0, px1, pz0, pz1, mus] of S.patches) {
    const ax = Math.max(px0, x0), bx = Math.min(px1, x1), az = Math.max(pz0, z0), bz = Math.min(pz1, z1);
    if (!(ax < bx && az < bz)) continue;
    const m = 24, pos = [], idx = [];
    for (let j = 0; j <= m; j++) {
      for (let i = 0; i <= m; i++) {
        const x = ax + (bx - ax) * i / m, z = az + (bz - az) * j / m;
        pos.push(x, h(x, z) + lift, z);
      }
    }
    for (let j = 0; j < m; j++) {
      for (let i = 0; i < m; i++) {
        const k = j * (m + 1) + i;
        idx.push(k, k + m + 1, k + 1, k + 1, k + m + 1, k + m + 2);
      }
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    g.setIndex(idx);
    const slip = Math.max(0, Math.min(1, 1 - mus));
    const color = new THREE.Color().setRGB(0.9 - 0.6 * slip, 0.9 - 0.3 * slip, 1.0);
    const mesh = new THREE.Mesh(g, new THREE.MeshBasicMaterial({ color, transparent: true, opacity: 0.55, side: THREE.DoubleSide, depthWrite: false }));
    mesh.name = `friction patch muS=${mus}`;
    scene.add(mesh);
  }
}

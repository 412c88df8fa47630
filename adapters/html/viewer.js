// geobrep's offline model viewer: the model embedded in the page, drawn with three.js.
// Objects listed with their colours and switchable, a clipping plane, a box of axes labelled
// with world coordinates. Reports what it shows on the console ("geobrep-view: {...}").
(function () {
  "use strict";
  const T = window.THREE;
  const model = JSON.parse(document.getElementById("geobrep-model").textContent);
  const origin = model.origin;

  function decode(text, Type) {
    const bytes = Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
    return new Type(bytes.buffer);
  }

  function report(extra) {
    const line = JSON.stringify(Object.assign({
      title: model.title,
      crs: model.crs,
      objects: model.objects.map((o) => o.name),
      types: model.objects.map((o) => o.type),
      markers: model.objects.filter((o) => o.markers).reduce((n, o) => n + o.markers.names.length, 0),
      triangles: model.objects.reduce((n, o) => n + (o.mode === 4 ? o.count / 3 : 0), 0),
    }, extra));
    document.getElementById("geobrep-report").textContent = line;
    console.log("geobrep-view: " + line);
  }

  const canvas = document.getElementById("view");
  let renderer;
  try {
    renderer = new T.WebGLRenderer({ canvas: canvas, antialias: true, preserveDrawingBuffer: true });
  } catch (error) {
    document.getElementById("status").textContent = "WebGL is not available: " + error.message;
    report({ webgl: false });
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.localClippingEnabled = true;
  const scene = new T.Scene();
  scene.background = new T.Color(0xffffff);
  scene.add(new T.AmbientLight(0xffffff, 1.2));
  const sun = new T.DirectionalLight(0xffffff, 1.8);
  scene.add(sun);

  const low = new T.Vector3(...model.bounds[0]);
  const high = new T.Vector3(...model.bounds[1]);
  const size = new T.Vector3().subVectors(high, low);
  const centre = new T.Vector3().addVectors(low, high).multiplyScalar(0.5);
  const radius = Math.max(size.length() / 2, 1e-6);
  const clip = new T.Plane(new T.Vector3(-1, 0, 0), 0);
  const clipping = [];

  const group = new T.Group();
  scene.add(group);
  const drawn = model.objects.map((object) => {
    const geometry = new T.BufferGeometry();
    geometry.setAttribute("position", new T.BufferAttribute(decode(object.positions, Float32Array), 3));
    if (object.indices) {
      geometry.setIndex(new T.BufferAttribute(decode(object.indices, Uint32Array), 1));
    }
    const colour = new T.Color(object.colour);
    let item;
    if (object.mode === 4) {
      geometry.computeVertexNormals();
      const shaded = Boolean(object.colours);  // a grid coloured by a property
      if (shaded) {
        geometry.setAttribute("color", new T.BufferAttribute(decode(object.colours, Uint8Array), 3, true));
      }
      item = new T.Mesh(geometry, new T.MeshLambertMaterial({
        color: shaded ? 0xffffff : colour, vertexColors: shaded, side: T.DoubleSide, clippingPlanes: clipping,
        polygonOffset: object.type !== "Surface", polygonOffsetFactor: 1, polygonOffsetUnits: 1,
      }));
    } else if (object.mode === 1) {
      item = new T.LineSegments(geometry, new T.LineBasicMaterial({ color: colour, clippingPlanes: clipping }));
    } else {
      item = new T.Points(geometry, new T.PointsMaterial({ color: colour, size: 4, sizeAttenuation: false, clippingPlanes: clipping }));
    }
    if (object.markers) {  // a well's markers: points and their names, switched with the well
      const trace = item;
      item = new T.Group();
      item.add(trace);
      const picks = new T.BufferGeometry();
      const at = decode(object.markers.positions, Float32Array);
      picks.setAttribute("position", new T.BufferAttribute(at, 3));
      item.add(new T.Points(picks, new T.PointsMaterial({ color: colour, size: 9, sizeAttenuation: false, clippingPlanes: clipping })));
      object.markers.names.forEach((name, i) => {
        const where = new T.Vector3(at[3 * i], at[3 * i + 1], at[3 * i + 2]);
        label(name, where.add(new T.Vector3(radius * 0.02, 0, 0)), radius * 0.04, item);
      });
    }
    item.name = object.name;
    item.visible = object.visible;
    group.add(item);
    return item;
  });

  // the list: one row per object, grouped by type, with its colour and a switch
  const list = document.getElementById("objects");
  const headings = {
    Block: "Blocks", Surface: "Surfaces", PolyLine: "Lines", PointSet: "Points",
    RegularGrid: "Regular grids", StructuredGrid: "Structured grids", Well: "Wells",
  };
  Object.keys(headings).forEach((type) => {
    const members = model.objects.map((o, i) => [o, i]).filter(([o]) => o.type === type);
    if (!members.length) return;
    const title = document.createElement("h3");
    title.textContent = headings[type];
    list.appendChild(title);
    members.forEach(([object, index]) => {
      const row = document.createElement("label");
      row.className = "row";
      const box = document.createElement("input");
      box.type = "checkbox";
      box.checked = object.visible;
      box.dataset.name = object.name;
      box.addEventListener("change", () => { drawn[index].visible = box.checked; draw(); });
      const swatch = document.createElement("span");
      swatch.className = "swatch";
      swatch.style.background = object.colour;
      const text = document.createElement("span");
      text.textContent = object.name + (object.detail ? " (" + object.detail + ")" : "");
      row.append(box, swatch, text);
      list.appendChild(row);
    });
  });

  // the clipping plane: an axis, a position in world coordinates, a side
  const axisChoice = document.getElementById("clip-axis");
  const slider = document.getElementById("clip-at");
  const flip = document.getElementById("clip-flip");
  const readout = document.getElementById("clip-value");
  function updateClip() {
    const axis = axisChoice.value;
    if (axis === "none") {
      clipping.length = 0;
      readout.textContent = "";
    } else {
      const k = { x: 0, y: 1, z: 2 }[axis];
      const at = low.getComponent(k) + size.getComponent(k) * Number(slider.value) / 1000;
      const normal = new T.Vector3();
      normal.setComponent(k, flip.checked ? 1 : -1);
      clip.normal.copy(normal);
      clip.constant = flip.checked ? -at : at;
      clipping.length = 0;
      clipping.push(clip);
      readout.textContent = axis.toUpperCase() + " = " + (at + origin[k]).toFixed(1);
    }
    draw();
  }
  [axisChoice, slider, flip].forEach((el) => el.addEventListener("input", updateClip));

  // axes: the model's box with ticks labelled in world coordinates
  const boxLines = new T.LineSegments(
    new T.EdgesGeometry(new T.BoxGeometry(size.x, size.y, size.z)),
    new T.LineBasicMaterial({ color: 0x555555 }));
  boxLines.position.copy(centre);
  scene.add(boxLines);
  function label(text, position, height, parent) {
    const canvas2d = document.createElement("canvas");
    const context = canvas2d.getContext("2d");
    context.font = "48px sans-serif";
    const width = Math.ceil(context.measureText(text).width) + 16;
    canvas2d.width = width;
    canvas2d.height = 64;
    context.font = "48px sans-serif";
    context.fillStyle = "#222";
    context.fillText(text, 8, 48);
    const sprite = new T.Sprite(new T.SpriteMaterial({ map: new T.CanvasTexture(canvas2d), depthTest: false }));
    sprite.scale.set(height * width / 64, height, 1);
    sprite.position.copy(position);
    (parent || scene).add(sprite);
    return sprite;
  }
  function niceStep(span) {
    const raw = span / 4;
    const power = Math.pow(10, Math.floor(Math.log10(raw)));
    return [1, 2, 5, 10].map((m) => m * power).find((s) => s >= raw);
  }
  const textHeight = radius * 0.045;
  const tick = radius * 0.03;
  const axisNames = model.axis_names;
  // each axis along a visible edge of the box: x in front, y on the left, z on the right
  const edges = [
    { start: [null, low.y, low.z], out: [0, -1, 0] },
    { start: [low.x, null, low.z], out: [-1, 0, 0] },
    { start: [high.x, low.y, null], out: [1, 0, 0] },
  ];
  [0, 1, 2].forEach((k) => {
    const span = size.getComponent(k);
    if (!(span > 0)) return;
    const step = niceStep(span);
    const first = Math.ceil((low.getComponent(k) + origin[k]) / step) * step;
    const out = new T.Vector3(...edges[k].out).multiplyScalar(tick);
    const points = [];
    const last = high.getComponent(k) + origin[k] + step * 1e-6;
    for (let i = 0, world = first; world <= last; i += 1, world = first + i * step) {
      const at = new T.Vector3(...edges[k].start.map((v, j) => (j === k ? world - origin[k] : v)));
      points.push(at.x, at.y, at.z, at.x + out.x, at.y + out.y, at.z + out.z);
      label(String(Math.round(world * 100) / 100), at.clone().addScaledVector(out, 4.5), textHeight);
    }
    const ticks = new T.BufferGeometry();
    ticks.setAttribute("position", new T.Float32BufferAttribute(points, 3));
    scene.add(new T.LineSegments(ticks, new T.LineBasicMaterial({ color: 0x222222 })));
    const middle = new T.Vector3(...edges[k].start.map((v, j) => (j === k ? centre.getComponent(k) : v)));
    label(axisNames[k], middle.addScaledVector(out, 11), textHeight * 1.3);
  });

  const camera = new T.PerspectiveCamera(35, 1, radius / 100, radius * 100);
  camera.up.set(0, 0, 1);
  camera.position.copy(centre).add(new T.Vector3(-1.2, -1.9, 1.1).normalize().multiplyScalar(radius * 3.4));
  const controls = new T.OrbitControls(camera, canvas);
  controls.target.copy(centre);
  controls.addEventListener("change", draw);

  function resize() {
    const width = canvas.clientWidth, height = canvas.clientHeight;
    renderer.setSize(width, height, false);
    camera.aspect = width / Math.max(height, 1);
    camera.updateProjectionMatrix();
    draw();
  }
  function draw() {
    sun.position.copy(camera.position);
    renderer.render(scene, camera);
  }
  window.addEventListener("resize", resize);
  controls.update();
  resize();
  // a clipping plane from the address: model.html#clip=x:0.5 (fraction of the box), :flip
  const wanted = /clip=([xyz]):([0-9.]+)(:flip)?/.exec(window.location.hash);
  if (wanted) {
    axisChoice.value = wanted[1];
    slider.value = String(Math.round(Math.min(Number(wanted[2]), 1) * 1000));
    flip.checked = Boolean(wanted[3]);
    updateClip();
  }
  document.getElementById("status").textContent = "";
  report({ webgl: true, three: T.REVISION, clip: readout.textContent });
  window.geobrepViewer = { scene: scene, objects: drawn, draw: draw, camera: camera };
})();

// An msm scene description (scenes/*.json, parsed) as a three.js scene, for the browser tests that
// render the same scene with msm's renderer and ray tracer: the primitives are msm's own
// (src/scene/primitives.cpp: the same vertices, normals and triangles), the transforms msm's
// (world = translate * rotate * scale, Euler rotations applied X, then Y, then Z), the camera its
// look-at and vertical field of view, the light its one directional light with the explicit
// shadow framing (the same orthographic map: centre, extent, depth range, the map's up (0, 1, 0),
// or (0, 0, 1) for a light within 8° of vertical, as Scene::light_view), or its one point light
// ("lights": [{ "type": "point" }]: its range the shadow camera's far plane, the near one at 1e-3 of
// the range as msm's, which clips nothing in front of a caster). Both sides of every surface cast
// (msm's depth pass culls nothing). Anything else is refused with an Error naming it.
import * as THREE from 'three';

function grid(nu, nv, vertex) {
  const positions = [], normals = [], indices = [];
  for (let j = 0; j <= nv; ++j)
    for (let i = 0; i <= nu; ++i) {
      const { p, n } = vertex(i, j);
      positions.push(...p);
      normals.push(...n);
    }
  const row = nu + 1;
  for (let j = 0; j < nv; ++j)
    for (let i = 0; i < nu; ++i) {
      const a = j * row + i, b = a + 1, c = a + row, d = c + 1;
      indices.push(a, b, d, a, d, c);
    }
  return { positions, normals, indices };
}

// Six faces of four vertices each, as add_box.
const BOX_FACES = [
  [[1, 0, 0], [0, 0, -1], [0, 1, 0]], [[-1, 0, 0], [0, 0, 1], [0, 1, 0]],
  [[0, 1, 0], [1, 0, 0], [0, 0, -1]], [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
  [[0, 0, 1], [1, 0, 0], [0, 1, 0]], [[0, 0, -1], [-1, 0, 0], [0, 1, 0]],
];
function addBox(mesh, lo, hi) {
  const c = lo.map((v, k) => 0.5 * (v + hi[k])), h = lo.map((v, k) => 0.5 * (hi[k] - v));
  const along = (axis) => axis.map((v) => v * Math.abs(axis[0]) * h[0] + v * Math.abs(axis[1]) * h[1] + v * Math.abs(axis[2]) * h[2]);
  for (const [n, u, v] of BOX_FACES) {
    const pn = along(n), pu = along(u), pv = along(v);
    const base = mesh.positions.length / 3;
    for (const [ku, kv] of [[-1, -1], [1, -1], [1, 1], [-1, 1]]) {
      mesh.positions.push(...c.map((x, k) => x + pn[k] + ku * pu[k] + kv * pv[k]));
      mesh.normals.push(...n);
    }
    mesh.indices.push(base, base + 1, base + 2, base, base + 2, base + 3);
  }
}

function cylinder({ radius = 0.5, height = 1, segments = 64, caps = true }) {
  const h = 0.5 * height;
  const ring = (i) => {
    const phi = (2 * Math.PI * (i % segments)) / segments;
    return [Math.cos(phi), 0, -Math.sin(phi)];
  };
  const mesh = grid(segments, 1, (i, j) => {
    const n = ring(i);
    return { p: [radius * n[0], j === 0 ? -h : h, radius * n[2]], n };
  });
  if (caps)
    for (const side of [-1, 1]) {
      const centre = mesh.positions.length / 3;
      mesh.positions.push(0, side * h, 0);
      mesh.normals.push(0, side, 0);
      for (let i = 0; i < segments; ++i) {
        const d = ring(i);
        mesh.positions.push(radius * d[0], side * h, radius * d[2]);
        mesh.normals.push(0, side, 0);
      }
      for (let i = 0; i < segments; ++i) mesh.indices.push(centre, centre + 1 + i, centre + 1 + ((i + 1) % segments));
    }
  return mesh;
}

function fence({ length = 4, height = 1, bars = 9, bar_width = 0.05, bar_depth = 0.05, rails = 2, rail_height = 0.05 }) {
  const mesh = { positions: [], normals: [], indices: [] };
  const hd = 0.5 * bar_depth;
  for (let i = 0; i < bars; ++i) {
    const x = bars === 1 ? 0 : -0.5 * (length - bar_width) + (i * (length - bar_width)) / (bars - 1);
    addBox(mesh, [x - 0.5 * bar_width, 0, -hd], [x + 0.5 * bar_width, height, hd]);
  }
  for (let k = 0; k < rails; ++k) {
    const top = (height * (rails - k)) / rails;
    addBox(mesh, [-0.5 * length, top - rail_height, -hd], [0.5 * length, top, hd]);
  }
  return mesh;
}

const PRIMITIVES = {
  plane: ({ size = [10, 10], subdivisions = [1, 1] }) =>
    grid(subdivisions[0], subdivisions[1], (i, j) => {
      const u = i / subdivisions[0], v = j / subdivisions[1];
      return { p: [(u - 0.5) * size[0], 0, (v - 0.5) * size[1]], n: [0, 1, 0] };
    }),
  box: ({ size = [1, 1, 1] }) => {
    const mesh = { positions: [], normals: [], indices: [] };
    addBox(mesh, size.map((s) => -0.5 * s), size.map((s) => 0.5 * s));
    return mesh;
  },
  cylinder,
  fence,
};

// Counter-clockwise seen from where the normals point (detail::fix_winding): three.js culls by it.
function geometry({ positions, normals, indices }) {
  const p = (k) => new THREE.Vector3().fromArray(positions, 3 * k), n = (k) => new THREE.Vector3().fromArray(normals, 3 * k);
  for (let t = 0; t < indices.length; t += 3) {
    const [a, b, c] = indices.slice(t, t + 3);
    const e = p(b).sub(p(a)).cross(p(c).sub(p(a)));
    if (e.dot(n(a).add(n(b)).add(n(c))) < 0) [indices[t + 1], indices[t + 2]] = [c, b];
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  g.setAttribute('normal', new THREE.Float32BufferAttribute(normals, 3));
  g.setIndex(indices);
  return g;
}

function placeObject(object, { translate = [0, 0, 0], rotate, scale = 1 } = {}) {
  object.position.fromArray(translate);
  if (Array.isArray(rotate)) object.rotation.set(...rotate.map(THREE.MathUtils.degToRad), 'ZYX'); // Rz Ry Rx
  else if (rotate) object.quaternion.setFromAxisAngle(new THREE.Vector3().fromArray(rotate.axis).normalize(), THREE.MathUtils.degToRad(rotate.angle_deg));
  if (Array.isArray(scale)) object.scale.fromArray(scale);
  else object.scale.setScalar(scale);
}

// { scene, camera, light } of the msm scene `description` for an image of aspect `aspect`;
// `material(doubleSided)` makes each object's material (the tests compare shadows, not colours).
export function buildMsmScene(description, aspect, material) {
  const name = description.name ?? 'scene';
  const refuse = (what) => {
    throw new Error(`msm scene '${name}': ${what} is not built for three.js`);
  };
  const point = description.lights?.length === 1 && description.lights[0].type === 'point' && !description.light;
  const framing = description.shadow_map ?? {};
  if (!point && framing.framing !== 'explicit') refuse(`shadow framing '${framing.framing ?? 'fit'}' (give an explicit one)`);
  if (!point && (!description.light || description.lights)) refuse('a scene without exactly one directional "light" or one point light');
  const scene = new THREE.Scene();
  for (const object of description.objects) {
    const type = object.primitive?.type;
    if (!(type in PRIMITIVES)) refuse(`object '${object.name}' (${object.mesh ? 'a mesh file' : `primitive ${type}`})`);
    const m = typeof object.material === 'string' ? description.materials?.[object.material] : object.material;
    const mesh = new THREE.Mesh(geometry(PRIMITIVES[type](object.primitive)), material(m?.double_sided === true));
    mesh.name = object.name ?? '';
    placeObject(mesh, object.transform);
    mesh.castShadow = mesh.receiveShadow = true;
    scene.add(mesh);
  }
  const c = description.camera;
  const camera = new THREE.PerspectiveCamera(c.fov_y_deg ?? 45, aspect, c.near ?? 0.1, c.far ?? 1000);
  camera.position.fromArray(c.position);
  camera.up.fromArray(c.up ?? [0, 1, 0]);
  camera.lookAt(new THREE.Vector3().fromArray(c.target));
  camera.updateMatrixWorld();

  if (point) {
    const { position, range, radius = 0 } = description.lights[0];
    if (radius !== 0 || !(range > 0)) refuse('a point light with a radius or without a range');
    const light = new THREE.PointLight(0xffffff, 1, range, 2);
    light.position.fromArray(position);
    light.shadow.camera.near = 1e-3 * range;
    light.castShadow = true;
    scene.add(light);
    return { scene, camera, light };
  }
  const towards = new THREE.Vector3().fromArray(description.light.towards_light).normalize();
  if (description.light.x_axis) refuse('a light with an x_axis');
  const light = new THREE.DirectionalLight(0xffffff, 1);
  const centre = new THREE.Vector3().fromArray(framing.center);
  light.position.copy(centre);
  light.target.position.copy(centre).sub(towards);
  light.shadow.camera.up.set(0, ...(Math.abs(towards.y) > 0.99 ? [0, 1] : [1, 0]));
  const [w, h] = framing.extent, [near, far] = framing.depth_range;
  Object.assign(light.shadow.camera, { left: -w / 2, right: w / 2, bottom: -h / 2, top: h / 2, near, far });
  light.shadow.camera.updateProjectionMatrix();
  light.castShadow = true;
  scene.add(light, light.target);
  return { scene, camera, light };
}

// The example scene: a ground, a railing of thin posts, columns around a point light and a
// directional sun and a spot light; shared by the example page and the browser tests.
import * as THREE from 'three';

export function buildScene({ pointLight = true, spotLight = false, sunLight = true } = {}) {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x9fb4c8);
  const stone = new THREE.MeshStandardMaterial({ color: 0xd8d2c4, roughness: 0.8 });
  const metal = new THREE.MeshStandardMaterial({ color: 0x4a4f57, roughness: 0.4, metalness: 0.6 });
  const ground = new THREE.Mesh(new THREE.PlaneGeometry(40, 40), stone);
  ground.rotation.x = -Math.PI / 2;
  ground.receiveShadow = true;
  ground.name = 'ground';
  scene.add(ground);
  // The railing: a top rail and thin balusters, whose shadows are where VSM leaks light.
  const railing = new THREE.Group();
  railing.name = 'railing';
  for (let i = -12; i <= 12; ++i) {
    const post = new THREE.Mesh(new THREE.BoxGeometry(0.12, 1.6, 0.12), metal);
    post.position.set(i * 0.35, 0.8, -2);
    railing.add(post);
  }
  const rail = new THREE.Mesh(new THREE.BoxGeometry(9, 0.12, 0.16), metal);
  rail.position.set(0, 1.6, -2);
  railing.add(rail);
  railing.traverse((o) => { o.castShadow = true; o.receiveShadow = true; });
  scene.add(railing);
  // Columns around the point light.
  for (let k = 0; k < 6; ++k) {
    const a = (k / 6) * Math.PI * 2;
    const column = new THREE.Mesh(new THREE.CylinderGeometry(0.35, 0.35, 3, 24), stone);
    column.position.set(8 + 2.5 * Math.cos(a), 1.5, 4 + 2.5 * Math.sin(a));
    column.castShadow = column.receiveShadow = true;
    scene.add(column);
  }
  const sun = new THREE.DirectionalLight(0xffffff, 2.5);
  sun.name = 'sun';
  sun.position.set(-6, 10, -10);
  sun.castShadow = true;
  sun.visible = sunLight;
  sun.shadow.mapSize.set(1024, 1024);
  Object.assign(sun.shadow.camera, { left: -12, right: 12, top: 12, bottom: -12, near: 1, far: 40 });
  scene.add(sun);
  scene.add(new THREE.HemisphereLight(0xbfd4ff, 0x403830, 0.6));
  const lights = { sun };
  if (pointLight) {
    const lamp = new THREE.PointLight(0xffd08a, 40, 20);
    lamp.name = 'lamp';
    lamp.position.set(8, 1.5, 4);
    lamp.castShadow = true;
    scene.add(lamp);
    lights.lamp = lamp;
  }
  if (spotLight) {
    const spot = new THREE.SpotLight(0xffffff, 60, 30, Math.PI / 6, 0.3);
    spot.name = 'spot';
    spot.position.set(6, 6, -7);
    spot.target.position.set(0, 0, -2);
    spot.castShadow = true;
    spot.shadow.mapSize.set(1024, 1024);
    scene.add(spot, spot.target);
    lights.spot = spot;
  }
  const camera = new THREE.PerspectiveCamera(50, 16 / 9, 0.1, 100);
  camera.position.set(0, 6, 9);
  camera.lookAt(1, 0, -1);
  return { scene, camera, lights };
}

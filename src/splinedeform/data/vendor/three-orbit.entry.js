// Entry of the vendored three.js bundle inlined into splinedeform viewer.html (see README.md).
export {
  WebGLRenderer, Scene, PerspectiveCamera, BufferGeometry, BufferAttribute, Mesh,
  MeshPhongMaterial, LineSegments, LineBasicMaterial, Points, PointsMaterial,
  AmbientLight, DirectionalLight, HemisphereLight, Color, Box3, Vector3, Sphere, DoubleSide,
  REVISION, ShaderMaterial,
} from 'three';
export { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

// A minimal OpenEXR writer: one part, scanlines, no compression, 32-bit float channels (what msm
// compare reads beside msm's own shadow buffers). `channels`: { name: array of width x height
// values, rows from the top }.
export function encodeExr(width, height, channels) {
  const names = Object.keys(channels).sort(); // EXR lists channels in alphabetical order
  const header = [];
  const bytes = (n, fill) => {
    const b = Buffer.alloc(n);
    fill(b);
    header.push(b);
  };
  const text = (s) => header.push(Buffer.from(`${s}\0`, 'latin1'));
  const attribute = (name, type, size, fill) => {
    text(name);
    text(type);
    bytes(4, (b) => b.writeInt32LE(size));
    bytes(size, fill);
  };
  bytes(8, (b) => {
    b.writeUInt32LE(20000630); // magic
    b.writeUInt32LE(2, 4); // version 2, single-part scanline
  });
  const chlistSize = names.reduce((s, n) => s + n.length + 1 + 16, 1);
  attribute('channels', 'chlist', chlistSize, (b) => {
    let o = 0;
    for (const n of names) {
      o += b.write(`${n}\0`, o, 'latin1');
      b.writeInt32LE(2, o); // FLOAT
      b.writeInt32LE(1, o + 8); // x sampling (pLinear and reserved are zero)
      b.writeInt32LE(1, o + 12); // y sampling
      o += 16;
    }
  });
  attribute('compression', 'compression', 1, () => {}); // NO_COMPRESSION
  const box = (b) => {
    b.writeInt32LE(width - 1, 8);
    b.writeInt32LE(height - 1, 12);
  };
  attribute('dataWindow', 'box2i', 16, box);
  attribute('displayWindow', 'box2i', 16, box);
  attribute('lineOrder', 'lineOrder', 1, () => {}); // INCREASING_Y
  attribute('pixelAspectRatio', 'float', 4, (b) => b.writeFloatLE(1));
  attribute('screenWindowCenter', 'v2f', 8, () => {});
  attribute('screenWindowWidth', 'float', 4, (b) => b.writeFloatLE(1));
  header.push(Buffer.alloc(1)); // end of header
  const headerSize = header.reduce((s, b) => s + b.length, 0);
  const lineData = 4 * width * names.length;
  const offsets = Buffer.alloc(8 * height);
  const lines = [];
  for (let y = 0; y < height; ++y) {
    offsets.writeBigUInt64LE(BigInt(headerSize + 8 * height + y * (8 + lineData)), 8 * y);
    const line = Buffer.alloc(8 + lineData);
    line.writeInt32LE(y);
    line.writeInt32LE(lineData, 4);
    names.forEach((n, c) => {
      for (let x = 0; x < width; ++x) line.writeFloatLE(channels[n][y * width + x], 8 + 4 * (c * width + x));
    });
    lines.push(line);
  }
  return Buffer.concat([...header, offsets, ...lines]);
}

// A typed array of `Type` from base64 of its bytes (as the test pages send them).
export function typedFromBase64(Type, text) {
  const bytes = Buffer.from(text, 'base64');
  return new Type(new Uint8Array(bytes).buffer); // a copy: Buffer's pool need not align
}

// A shadow buffer of test/same-scene.html (visibility and background as base64 of a Float32Array
// and a Uint8Array), as the channels encodeExr writes.
export function shadowBufferFromBase64({ visibility, background }) {
  return { visibility: typedFromBase64(Float32Array, visibility), background: typedFromBase64(Uint8Array, background) };
}

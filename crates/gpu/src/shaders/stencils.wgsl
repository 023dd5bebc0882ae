// Applies a stencil table in compressed-row form to columns of f32 values: row r of the
// destination is the sum over the row's entries k of weights[k] * source row indices[k],
// for each of the `width` interleaved columns. One invocation per destination row.
//
// `Real` is the type of the weights and of the sum: f64 where the adapter has 64-bit
// floats, else f32 (the Rust side defines it in front of this text). Compensated f32
// summation is no substitute: shader compilers may reassociate floating point (Mesa does),
// which undoes it; blocked summation (below) survives that.

struct Params {
    rows: u32,
    width: u32,
    // Rows per line of the dispatch grid (a grid may be two-dimensional when one
    // dimension cannot hold every workgroup).
    rows_per_line: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> offsets: array<u32>;
@group(0) @binding(2) var<storage, read> indices: array<u32>;
@group(0) @binding(3) var<storage, read> weights: array<Real>;
@group(0) @binding(4) var<storage, read> src: array<f32>;
@group(0) @binding(5) var<storage, read_write> dst: array<f32>;

@compute @workgroup_size(64)
fn apply(@builtin(global_invocation_id) id: vec3<u32>) {
    let row = id.x + id.y * params.rows_per_line;
    if (row >= params.rows) {
        return;
    }
    let begin = offsets[row];
    let end = offsets[row + 1u];
    let width = params.width;
    for (var c = 0u; c < width; c++) {
        // Blocks of 16 entries summed apart, then the blocks: a long row (a face point of
        // valence 360, a composed table) loses about 16 + n / 16 roundings, not n.
        var sum = Real(0.0);
        var k = begin;
        while (k < end) {
            let block_end = min(k + 16u, end);
            var block = Real(0.0);
            for (; k < block_end; k++) {
                block += weights[k] * Real(src[indices[k] * width + c]);
            }
            sum += block;
        }
        dst[row * width + c] = f32(sum);
    }
}

// Empties the queue of rays the pre-trace leaves for the BVH (its count, word 0).

@group(0) @binding(0) var<storage, read_write> queue: array<u32>;

@compute @workgroup_size(1, 1, 1)
fn main() {
    queue[0] = 0u;
}

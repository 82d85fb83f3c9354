//! The optimal collapse (`widen`, `Optimal`): a valid
//! wide tree over the binary tree's leaves, in their order, with a true stack
//! bound, never costlier than the greedy collapse, and on small trees the
//! cheapest of every collapse there is, and of those the shallowest.

use super::area;
use crate::gpu::layout::{child_ref, Bounds, Bvh, GpuBvhNode};
use crate::scene::accel::tests::{check, check_wide_tree};
use crate::scene::random::Rng;
use crate::scene::Scene;

/// The random scenes' SplitMix64: the trees are the same every run, from
/// the seed alone.
fn below(rng: &mut Rng, n: usize) -> usize {
    (rng.next() % n as u64) as usize
}

fn unit(rng: &mut Rng) -> f32 {
    (rng.next() >> 40) as f32 / (1u64 << 24) as f32
}

fn union((amin, amax): Bounds, (bmin, bmax): Bounds) -> Bounds {
    let mut b = (amin, amax);
    for a in 0..3 {
        b.0[a] = amin[a].min(bmin[a]);
        b.1[a] = amax[a].max(bmax[a]);
    }
    b
}

/// A random binary tree over `leaves` leaves (one primitive each, in order),
/// laid out depth-first as the builder lays its trees out: shapes from
/// balanced to a chain, each leaf a random box or, with `same`, all one box
/// (as the sphere list's identical spheres make them), each node's box the
/// union of its children's.
fn random_tree(rng: &mut Rng, leaves: usize, same: bool) -> Bvh {
    fn grow(
        rng: &mut Rng,
        first: usize,
        count: usize,
        same: bool,
        nodes: &mut Vec<GpuBvhNode>,
    ) -> (Bounds, u32, u32) {
        if count == 1 {
            let b = if same {
                ([0.0; 3], [1.0; 3])
            } else {
                let min = [0; 3].map(|_| 10.0 * unit(rng));
                let mut max = min;
                for m in &mut max {
                    *m += 0.01 + 3.0 * unit(rng);
                }
                (min, max)
            };
            return (b, child_ref::leaf(first as u32, 1), 1);
        }
        let left = match below(rng, 4) {
            0 => 1,
            1 => count - 1,
            _ => 1 + below(rng, count - 1),
        };
        let at = nodes.len();
        nodes.push(GpuBvhNode::default());
        let (lb, l, ld) = grow(rng, first, left, same, nodes);
        let (rb, r, rd) = grow(rng, first + left, count - left, same, nodes);
        nodes[at] = GpuBvhNode::new(lb, l, rb, r);
        (union(lb, rb), at as u32, 1 + ld.max(rd))
    }
    let mut nodes = Vec::new();
    let (_, _, depth) = grow(rng, 0, leaves, same, &mut nodes);
    Bvh {
        nodes,
        prims: (0..leaves as u32).collect(),
        depth,
        width: 2,
        ..Bvh::default()
    }
}

/// The leaves' references and boxes, depth-first, children in order, of a
/// binary tree (`nodes`) or a wide one.
fn leaves(b: &Bvh) -> Vec<(u32, Bounds)> {
    let children = |i: usize| -> Vec<(Bounds, u32)> {
        if b.width > 2 {
            b.wide_children(i).collect()
        } else {
            let n = &b.nodes[i];
            vec![
                ((n.left_min, n.left_max), n.left),
                ((n.right_min, n.right_max), n.right),
            ]
        }
    };
    let (mut out, mut todo) = (Vec::new(), vec![(([0.0; 3], [0.0; 3]), 0)]);
    while let Some((bounds, c)) = todo.pop() {
        if child_ref::as_leaf(c).is_some() {
            out.push((c, bounds));
        } else {
            todo.extend(children(c as usize).into_iter().rev());
        }
    }
    out
}

/// The summed areas of the wide tree's interior nodes but the root: what
/// the collapse minimises.
fn interior_area(b: &Bvh) -> f64 {
    let q = super::quads(b.width);
    (0..b.wide.len())
        .step_by(q)
        .flat_map(|i| b.wide_children(i))
        .filter(|&(_, c)| child_ref::as_leaf(c).is_none())
        .map(|(bounds, _)| area(bounds))
        .sum()
}

/// The greedy and the optimal collapse of `binary` at each width: both valid
/// with a true stack bound (`check_wide_tree`), the same leaves in the same
/// order as the binary tree, and the optimal one no costlier.
fn against_greedy(binary: &Bvh, what: &str) {
    let order = leaves(binary);
    for width in [4, 8] {
        let greedy = binary.clone().widen_greedy(width);
        let optimal = binary.clone().widen(width);
        for b in [&greedy, &optimal] {
            check_wide_tree(binary, b, width);
            assert!(
                leaves(b) == order,
                "{what} at width {width}: the leaves or their order"
            );
        }
        let (g, o) = (greedy.sah_cost(), optimal.sah_cost());
        // The table's costs are whole units of 2^-55 of the root's area per node.
        assert!(
            o <= g * (1.0 + 1e-9),
            "{what} at width {width}: optimal {o} > greedy {g}"
        );
        assert!(interior_area(&optimal) <= interior_area(&greedy) * (1.0 + 1e-9));
    }
}

#[test]
fn the_optimal_collapse_costs_no_more_than_the_greedy_one() {
    let spheres =
        |n: &str| Scene::load("spherelist", &[("extra_spheres".into(), n.into())]).unwrap();
    let mut scenes = vec![
        Scene::load("teapot", &[]).unwrap(),
        Scene::load("box", &[]).unwrap(),
        spheres("1000"),
        spheres("10000"),
    ];
    scenes.extend((1..=3).map(|seed| Scene::load(&format!("random:{seed}"), &[]).unwrap()));
    for scene in &scenes {
        against_greedy(&check(scene), &scene.name);
    }
    let mut rng = Rng(7);
    for (leaves, same) in [
        (2, false),
        (3, true),
        (200, false),
        (500, false),
        (500, true),
        (3000, false),
    ] {
        let tree = random_tree(&mut rng, leaves, same);
        against_greedy(
            &tree,
            &format!("a random tree of {leaves} leaves (same boxes: {same})"),
        );
    }
}

/// Every collapse of `binary` into nodes of at most `width` children, as the
/// set of interior nodes that stay nodes (the root always): each one's
/// interior-node area (`interior_area`), node count and depth.
fn every_collapse(binary: &Bvh, width: usize) -> Vec<(f64, u32, u32)> {
    let nodes = &binary.nodes;
    // Each interior node's box, as its parent holds it.
    let mut boxes = vec![([0.0; 3], [0.0; 3]); nodes.len()];
    for n in nodes {
        for (b, c) in [
            ((n.left_min, n.left_max), n.left),
            ((n.right_min, n.right_max), n.right),
        ] {
            if child_ref::as_leaf(c).is_none() {
                boxes[c as usize] = b;
            }
        }
    }
    // Node `i`'s wide children, those of the nodes it absorbs included: count and depth.
    fn cut(nodes: &[GpuBvhNode], kept: u32, i: usize) -> (usize, u32) {
        let (mut count, mut depth) = (0, 1);
        for c in [nodes[i].left, nodes[i].right] {
            if child_ref::as_leaf(c).is_some() {
                count += 1;
            } else if kept & (1 << c) != 0 {
                count += 1;
                depth = depth.max(1 + cut(nodes, kept, c as usize).1);
            } else {
                let (n, d) = cut(nodes, kept, c as usize);
                count += n;
                depth = depth.max(d);
            }
        }
        (count, depth)
    }
    let mut all = Vec::new();
    for rest in 0..1u32 << (nodes.len() - 1) {
        let kept = 1 | rest << 1;
        let ok = (0..nodes.len()).all(|i| kept & (1 << i) == 0 || cut(nodes, kept, i).0 <= width);
        if ok {
            let cost = (1..nodes.len())
                .filter(|i| kept & (1 << i) != 0)
                .map(|i| area(boxes[i]))
                .sum();
            all.push((cost, kept.count_ones(), 1 + cut(nodes, kept, 0).1));
        }
    }
    all
}

/// On random trees of up to 12 leaves, against every collapse there is: the
/// least cost; and where all boxes are one box, so that cost counts nodes
/// and ties abound, the fewest nodes and, of those, the least depth.
#[test]
fn the_optimal_collapse_is_the_cheapest_of_every_collapse() {
    let mut rng = Rng(2017);
    for t in 0..400 {
        let (leaves, same) = (2 + below(&mut rng, 11), t % 3 == 0);
        let tree = random_tree(&mut rng, leaves, same);
        for width in [4u32, 8] {
            let all = every_collapse(&tree, width as usize);
            let least = all.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
            let optimal = tree.clone().widen(width);
            let greedy = tree.clone().widen_greedy(width);
            check_wide_tree(&tree, &optimal, width);
            let what = format!("tree {t} ({leaves} leaves, same boxes: {same}) at width {width}");
            let found = interior_area(&optimal);
            assert!(
                (found - least).abs() <= 1e-9 * least.max(1.0),
                "{what}: {found}, the least is {least}"
            );
            assert!(
                interior_area(&greedy) >= least - 1e-9 * least.max(1.0),
                "{what}: greedy"
            );
            if same {
                let best = all.iter().map(|c| (c.1, c.2)).min().unwrap();
                assert_eq!((optimal.node_count() as u32, optimal.depth), best, "{what}");
            }
        }
    }
}

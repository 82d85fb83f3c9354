//! Proves that naga's layout of every struct in shaders/trace/*.glsl equals the
//! Rust mirror in common/src/gpu/layout.rs: member offsets, struct sizes, array strides.

use std::mem::{offset_of, size_of};
use twinray_common::gpu::layout::*;
use twinray_common::shader::build::{compute_source, fragment_source, parse};
use twinray_common::shader::variant::Variant;

/// (name, offset) of every member, in declaration order.
fn naga_members(module: &naga::Module, ty: naga::Handle<naga::Type>) -> (Vec<(String, u32)>, u32) {
    match &module.types[ty].inner {
        naga::TypeInner::Struct { members, span } => (
            members
                .iter()
                .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                .collect(),
            *span,
        ),
        other => panic!("expected a struct, found {other:?}"),
    }
}

/// As `naga_members`, with each member that is a fixed-size array spelled out
/// element by element (`bounds[0]`, `bounds[1]`, ...), for a GLSL array that
/// stands for consecutive Rust fields.
fn naga_elements(module: &naga::Module, ty: naga::Handle<naga::Type>) -> (Vec<(String, u32)>, u32) {
    let naga::TypeInner::Struct { members, span } = &module.types[ty].inner else {
        panic!("expected a struct");
    };
    let mut out = Vec::new();
    for m in members {
        let name = m.name.clone().unwrap_or_default();
        match &module.types[m.ty].inner {
            naga::TypeInner::Array {
                size: naga::ArraySize::Constant(n),
                stride,
                ..
            } => out.extend((0..n.get()).map(|i| (format!("{name}[{i}]"), m.offset + i * stride))),
            _ => out.push((name, m.offset)),
        }
    }
    (out, *span)
}

/// The block bound at `binding` and, for storage buffers, its runtime-array element type and stride.
fn block(
    module: &naga::Module,
    binding: u32,
) -> (
    naga::Handle<naga::Type>,
    Option<(naga::Handle<naga::Type>, u32)>,
) {
    let (_, var) = module
        .global_variables
        .iter()
        .find(|(_, v)| v.binding.as_ref().map(|b| (b.group, b.binding)) == Some((0, binding)))
        .unwrap_or_else(|| panic!("no resource at binding {binding}"));
    let elem = match &module.types[var.ty].inner {
        naga::TypeInner::Struct { members, .. } if members.len() == 1 => {
            match &module.types[members[0].ty].inner {
                naga::TypeInner::Array { base, stride, .. } => Some((*base, *stride)),
                _ => None,
            }
        }
        _ => None,
    };
    (var.ty, elem)
}

/// A Rust struct's layout as the checks take it: its name, the offsets of
/// the fields listed (`pad[1]`: the second u32 of an array field), its size.
struct RustLayout {
    name: &'static str,
    offsets: Vec<u32>,
    size: usize,
}

macro_rules! rust_layout {
    ($t:ident { $($field:tt $( [$idx:expr] )?),* $(,)? }) => {
        RustLayout {
            name: stringify!($t),
            offsets: vec![$( offset_of!($t, $field) as u32 $( + $idx * 4 )? ),*],
            size: size_of::<$t>(),
        }
    };
}

fn check(naga: (Vec<(String, u32)>, u32), rust: RustLayout) {
    let (members, span) = naga;
    let name = rust.name;
    let offsets: Vec<u32> = members.iter().map(|m| m.1).collect();
    assert_eq!(
        offsets, rust.offsets,
        "{name}: member offsets differ (naga members {members:?})"
    );
    assert_eq!(span as usize, rust.size, "{name}: size differs");
}

/// How naga spells out a struct's members: `naga_members` or `naga_elements`.
type Members = fn(&naga::Module, naga::Handle<naga::Type>) -> (Vec<(String, u32)>, u32);

/// The storage buffer at `binding` is a runtime array of `rust`: its stride
/// is the struct's size, and its element the struct's layout.
fn check_array(module: &naga::Module, binding: u32, members: Members, rust: RustLayout) {
    let (_, elem) = block(module, binding);
    let (ty, stride) =
        elem.unwrap_or_else(|| panic!("binding {binding} ({}) is no runtime array", rust.name));
    assert_eq!(stride as usize, rust.size, "{} stride", rust.name);
    check(members(module, ty), rust);
}

/// The all-features variant's module: it declares every struct but the ray counts.
fn generic_module() -> naga::Module {
    parse(
        &fragment_source(),
        naga::ShaderStage::Fragment,
        &Variant::generic(Default::default()),
    )
    .unwrap()
    .0
}

#[test]
fn naga_layout_matches_rust_for_every_shader_struct() {
    let module = generic_module();

    let (frame_ty, _) = block(&module, binding::FRAME);
    check(
        naga_members(&module, frame_ty),
        rust_layout!(GpuFrame {
            eye,
            min_weight,
            top_left,
            epsilon,
            step_x,
            max_depth,
            step_y,
            sphere_count,
            background,
            triangle_count,
            light_count,
            width,
            height,
            launch_grid
        }),
    );

    check_array(
        &module,
        binding::SPHERES,
        naga_members,
        rust_layout!(GpuSphere { center, radius, material, pad[0], pad[1], pad[2] }),
    );

    check_array(
        &module,
        binding::TRIANGLES,
        naga_members,
        rust_layout!(GpuTriangle {
            p0,
            material,
            p1,
            pad0,
            p2,
            pad1,
            n0,
            pad2,
            n1,
            pad3,
            n2,
            pad4
        }),
    );

    check_array(
        &module,
        binding::MATERIALS,
        naga_members,
        rust_layout!(GpuMaterial {
            ambient, reflectivity, diffuse, transparency, specular, shininess, ior, pad[0], pad[1], pad[2]
        }),
    );

    check_array(
        &module,
        binding::LIGHTS,
        naga_members,
        rust_layout!(GpuLight {
            position,
            pad0,
            color,
            pad1
        }),
    );
}

/// The BVH's nodes and leaf primitives (a test of their own: the architecture
/// test's 120-line limit).
#[test]
fn naga_layout_matches_rust_for_the_bvh() {
    let module = generic_module();
    check_array(
        &module,
        binding::BVH_NODES,
        naga_members,
        rust_layout!(GpuBvhNode {
            left_min,
            left,
            left_max,
            pad0,
            right_min,
            right,
            right_max,
            pad1
        }),
    );
    check_array(
        &module,
        binding::BVH_PRIMS,
        naga_members,
        rust_layout!(GpuBvhPrim {
            a,
            code,
            b,
            pad0,
            c,
            pad1
        }),
    );
}

/// The wide tree's node (`--accel bvh4`, `bvh8`), which only the wide variants
/// declare, at the binary node's binding.
#[test]
fn naga_layout_matches_rust_for_the_wide_bvh() {
    for width in [4, 8] {
        let mut variant = Variant::generic(Default::default());
        variant.bvh_stack = Some(4);
        variant.bvh_width = width;
        let (module, _) = parse(&fragment_source(), naga::ShaderStage::Fragment, &variant).unwrap();
        // The GLSL's `vec4 bounds[6]` is the six corner fields, in their order.
        check_array(
            &module,
            binding::BVH_NODES,
            naga_elements,
            rust_layout!(GpuBvhWideNode {
                min_x,
                min_y,
                min_z,
                max_x,
                max_y,
                max_z,
                child
            }),
        );
    }
}

/// The counting variant's per-pixel slots (`--count-rays`), which only it declares.
#[test]
fn naga_layout_matches_rust_for_the_ray_counts() {
    let (counting, _) = parse(
        &fragment_source(),
        naga::ShaderStage::Fragment,
        &Variant::generic(Default::default()).counting(),
    )
    .unwrap();
    check_array(
        &counting,
        binding::RAY_COUNTS,
        naga_members,
        rust_layout!(GpuRayCount {
            primary,
            shadow,
            mirror,
            glass_reflected,
            glass_refracted
        }),
    );
}

#[test]
fn every_builtin_variant_and_the_generic_one_compile_for_both_apis() {
    let mut variants = vec![Variant::generic(Default::default())];
    // Every numerical choice must compile too.
    use twinray_common::scene::numerics::Numerics;
    variants.extend(Numerics::all().map(Variant::generic));
    let scene = twinray_common::scene::Scene::load("box", &[]).unwrap();
    for width in [2, 4, 8] {
        let bvh = twinray_common::plan::build_bvh(&scene).widen(width);
        variants.push(Variant::for_scene(&scene, Some(&bvh)));
    }
    for (name, _) in twinray_common::scene::load::BUILTIN_SCENES {
        let scene = twinray_common::scene::Scene::load(name, &[]).unwrap();
        variants.push(Variant::for_scene(&scene, None));
    }
    for v in variants {
        let s = twinray_common::shader::build::build(&v)
            .unwrap_or_else(|e| panic!("{}: {e:#}", v.label()));
        assert_eq!(s.fragment.spirv[0], 0x0723_0203, "SPIR-V magic");
        assert!(
            s.fragment.glsl.starts_with("#version 450 core"),
            "{}",
            &s.fragment.glsl[..40]
        );
        assert!(
            s.fragment
                .glsl
                .contains("layout(std140, binding = 0) uniform"),
            "{}: UBO bound by number",
            v.label()
        );
    }
}

/// The generic fragment shader with the BVH compiled in, as naga reads it.
fn bvh_module() -> naga::Module {
    let mut variant = Variant::generic(Default::default());
    variant.bvh_stack = Some(4);
    parse(&fragment_source(), naga::ShaderStage::Fragment, &variant)
        .unwrap()
        .0
}

/// The literal that the shader's constant `name` is.
fn shader_constant(module: &naga::Module, name: &str) -> naga::Literal {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("the shader has no constant {name}"));
    match module.global_expressions[c.init] {
        naga::Expression::Literal(literal) => literal,
        ref other => panic!("{name} is {other:?}, not a literal"),
    }
}

/// The shader's own constants for what the BVH's words encode (trace/bvh.glsl)
/// equal the Rust ones that write those words.
#[test]
fn the_bvh_encodings_match_rust() {
    let module = bvh_module();
    let constant = |name: &str| shader_constant(&module, name);
    use naga::Literal::U32;
    assert_eq!(constant("SPHERE_BIT"), U32(PRIM_SPHERE_BIT));
    assert_eq!(constant("LEAF_BIT"), U32(child_ref::LEAF_BIT));
    assert_eq!(
        constant("LEAF_FIRST_SHIFT"),
        U32(child_ref::LEAF_FIRST_SHIFT)
    );
    assert_eq!(constant("GPU_ROOT"), U32(child_ref::GPU_ROOT));
    // NO_CHILD decodes to a leaf past the most primitives a tree may hold.
    let no_child = constant("NO_CHILD");
    let U32(no_child) = no_child else {
        panic!("NO_CHILD is {no_child:?}, not a u32");
    };
    let (first, _) = child_ref::as_leaf(no_child).expect("NO_CHILD is a leaf reference");
    assert!(first >= twinray_common::limits::MAX_BVH_PRIMITIVES);
}

/// The compute shader's flag for a tile that sees nothing is the bit the
/// launch order sets (plan::launch::EMPTY_TILE).
#[test]
fn the_empty_tile_flag_matches_rust() {
    let mut variant = Variant::generic(Default::default());
    variant.entry =
        twinray_common::shader::variant::Entry::Compute(twinray_common::cli::Workgroup {
            x: 8,
            y: 4,
        });
    let module = parse(&compute_source(), naga::ShaderStage::Compute, &variant)
        .unwrap()
        .0;
    assert_eq!(
        shader_constant(&module, "EMPTY_TILE"),
        naga::Literal::U32(twinray_common::plan::launch::EMPTY_TILE)
    );
}

/// The wide step's per-ray origin term, origin * inverse direction (padded by
/// ORIGIN_PAD, 2^-22, of itself), stays finite for every coordinate a scene may hold: the
/// shader's MIN_DIR bounds the inverse, limits::MAX_COORDINATE the origin.
#[test]
fn the_wide_steps_origin_term_stays_finite() {
    let module = bvh_module();
    let constant = |name: &str| -> f32 {
        match shader_constant(&module, name) {
            naga::Literal::F32(v) => v,
            other => panic!("{name} is {other:?}, not an f32"),
        }
    };
    assert_eq!(constant("ORIGIN_PAD"), 2f32.powi(-22));
    let largest = twinray_common::limits::MAX_COORDINATE as f32 * (1.0 / constant("MIN_DIR"));
    let padded = largest + largest * constant("ORIGIN_PAD");
    assert!(
        padded.is_finite() && padded < f32::MAX / 1.5,
        "MAX_COORDINATE / MIN_DIR = {largest:e} leaves no room below f32::MAX"
    );
}

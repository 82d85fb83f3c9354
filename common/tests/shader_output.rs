//! What the shader build hands the drivers: no per-invocation array
//! (function-local, or private at module scope) keeps
//! naga's zero initialiser (it costs every pixel a store per element, and on
//! NVIDIA's OpenGL a trip to local memory), in any variant, for either API,
//! on either path; and the tracer itself gives no array an initialiser, so the
//! post-passes only ever remove naga's.

use twinray_common::cli::RenderArgs;
use twinray_common::plan::build_bvh;
use twinray_common::plan::requests::Api;
use twinray_common::scene::load::BUILTIN_SCENES;
use twinray_common::scene::numerics::Numerics;
use twinray_common::scene::Scene;
use twinray_common::shader::build;
use twinray_common::shader::variant::Variant;

fn variants() -> Vec<Variant> {
    let mut v = Vec::new();
    for (name, _) in BUILTIN_SCENES {
        let scene = Scene::load(name, &[]).unwrap();
        let tree = build_bvh(&scene);
        for bvh in [None, Some(&tree)] {
            v.push(Variant::for_scene(&scene, bvh));
            v.push(Variant::specialized(&scene, bvh));
        }
        // The BVH stacks local to each walk, and the ray stack as four arrays.
        let mut local = Variant::for_scene(&scene, Some(&tree));
        local.knobs.local_bvh_stack = true;
        local.knobs.split_ray_stack = true;
        v.push(local);
    }
    v.extend(Numerics::all().map(Variant::generic));
    v
}

/// Function- or Private-storage OpVariables (per invocation) with an
/// initialiser whose type is an array.
fn initialised_local_arrays(words: &[u32]) -> usize {
    let mut arrays = std::collections::HashSet::new();
    let mut array_pointers = std::collections::HashSet::new();
    let mut found = 0;
    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        let inst = &words[i..i + count];
        match inst[0] & 0xffff {
            28 => {
                arrays.insert(inst[1]);
            }
            32 if matches!(inst[2], 6 | 7) && arrays.contains(&inst[3]) => {
                array_pointers.insert(inst[1]);
            }
            59 if matches!(inst[3], 6 | 7) && count == 5 && array_pointers.contains(&inst[1]) => {
                found += 1
            }
            _ => {}
        }
        i += count;
    }
    found
}

/// GLSL lines that declare a local or module-scope array with an
/// initialiser (a `const` array's first word is no type: not one of these).
fn initialised_glsl_arrays(glsl: &str) -> Vec<String> {
    glsl.lines()
        .filter(|l| !l.starts_with("const ") && l.contains("] = ") && l.trim_end().ends_with(");"))
        .filter(|l| {
            // A declaration is `T name[N]`; an element store is `name[i]`.
            let decl = l.split(" = ").next().unwrap_or("").trim();
            decl.ends_with(']') && decl.split_whitespace().count() == 2
        })
        .map(str::to_string)
        .collect()
}

#[test]
fn no_local_array_keeps_an_initialiser() {
    let variants = variants();
    assert!(variants.len() > 20);
    let mut arrays_seen = 0;
    for v in &variants {
        let s = build::build(v).unwrap_or_else(|e| panic!("{}: {e:#}", v.label()));
        let c = build::build_compute(v, Api::Vulkan.default_workgroup(true)).unwrap();
        for (what, words, glsl) in [
            ("fragment", &s.fragment.spirv, &s.fragment.glsl),
            ("compute", &c.stage.spirv, &c.stage.glsl),
        ] {
            assert_eq!(
                initialised_local_arrays(words),
                0,
                "{} {what} SPIR-V",
                v.label()
            );
            let lines = initialised_glsl_arrays(glsl);
            assert!(lines.is_empty(), "{} {what} GLSL: {lines:?}", v.label());
            arrays_seen += glsl
                .lines()
                .filter(|l| l.starts_with("    ") && l.trim_end().ends_with("];"))
                .count();
        }
    }
    assert!(arrays_seen > 0, "the tracer has local arrays to check");
}

#[test]
fn the_experiment_puts_the_initialisers_back() {
    // Proves the checks above can fail: naga's own output has them.
    use clap::Parser;
    let args = RenderArgs::try_parse_from(["twinray", "--experiment", "naga-zero-init"]).unwrap();
    let scene = Scene::load("teapot", &[]).unwrap();
    let mut v = Variant::for_scene(&scene, Some(&build_bvh(&scene)));
    v.passes = twinray_common::lab::changes(&args).passes;
    let s = build::build(&v).unwrap();
    assert!(initialised_local_arrays(&s.fragment.spirv) > 0);
    assert!(!initialised_glsl_arrays(&s.fragment.glsl).is_empty());
    // The module-scope BVH stack alone: the checks see a private array too.
    v.ray_stack = 1;
    let s = build::build(&v).unwrap();
    let module_scope: Vec<String> = initialised_glsl_arrays(&s.fragment.glsl)
        .into_iter()
        .filter(|l| !l.starts_with(' '))
        .collect();
    assert_eq!(module_scope.len(), 1, "{module_scope:?}");
    assert!(initialised_local_arrays(&s.fragment.spirv) > 0);
}

#[test]
fn trace_glsl_initialises_no_array_itself() {
    for (name, src) in [
        ("trace.glsl", build::TRACE_GLSL),
        ("trace.frag", build::TRACE_FRAG),
        ("trace.comp", build::TRACE_COMP),
    ] {
        for (n, line) in src.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if let Some((decl, _)) = code.split_once('=') {
                let decl = decl.trim();
                assert!(
                    !(decl.ends_with(']') && decl.split_whitespace().count() == 2),
                    "{name}:{}: an array with an initialiser: {line}",
                    n + 1
                );
            }
        }
    }
}

/// The apps compile what is on disk: every file of shaders/trace/ is a part,
/// and the tracer the build embeds is those files, read now, in their order.
#[test]
fn the_tracer_is_the_parts_on_disk() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders/trace");
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".glsl"))
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = build::TRACE_PARTS
        .iter()
        .map(|(n, _)| n.to_string())
        .collect();
    listed.sort();
    assert_eq!(
        on_disk, listed,
        "every part in shaders/trace/ is in TRACE_PARTS"
    );
    let mut expected = String::new();
    for (name, embedded) in build::TRACE_PARTS {
        let text = std::fs::read_to_string(dir.join(name)).unwrap();
        assert_eq!(
            embedded, text,
            "{name}: TRACE_PARTS holds the file as it is"
        );
        expected.push_str(&text);
    }
    let body = build::TRACE_GLSL.split_once('\n').unwrap().1;
    assert_eq!(
        body, expected,
        "TRACE_GLSL concatenates the parts in TRACE_PARTS's order"
    );
}

/// GLSL built-ins and constructors: pure and cheap, so evaluating them right
/// of `&&` or `||` regardless of the left side changes nothing.
const PURE_BUILTINS: &str = "abs all any bool clamp cross dot float greaterThan int length \
    max min mix normalize sign sqrt uint uvec2 uvec4 vec2 vec3 vec4";

/// Each `&&` or `||` whose right operand calls a function of the tracer or
/// indexes an array, as `part:line: operand`. naga's GLSL front end does not
/// short-circuit (gfx-rs/wgpu#4394): it evaluates that operand every time, so
/// a guard written as `i < COUNT && buf[i]...` reads past the buffer and
/// `cheap || costly()` always pays for the call.
fn unguarded_operands(part: &str, src: &str) -> Vec<String> {
    let code: String = src
        .lines()
        .map(|l| {
            let l = l.split("//").next().unwrap_or("");
            if l.trim_start().starts_with('#') {
                "\n".to_string()
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let bytes = code.as_bytes();
    let mut found = Vec::new();
    let mut i = 0;
    while i + 1 < bytes.len() {
        let op = &code[i..i + 2];
        if op != "&&" && op != "||" {
            i += 1;
            continue;
        }
        // The right operand: up to the next `&&`/`||`, `;`, `{` or `,` at its
        // own nesting level, or the `)` that closes the enclosing group.
        let start = i + 2;
        let mut depth = 0i32;
        let mut end = start;
        while end < bytes.len() {
            let rest = &code[end..];
            match bytes[end] {
                b'(' | b'[' => depth += 1,
                b')' | b']' if depth == 0 => break,
                b')' | b']' => depth -= 1,
                b';' | b'{' | b',' if depth == 0 => break,
                _ if depth == 0 && (rest.starts_with("&&") || rest.starts_with("||")) => break,
                _ => {}
            }
            end += 1;
        }
        let operand = &code[start..end];
        let calls_tracer = operand
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '('))
            .filter_map(|w| w.split_once('(').map(|(name, _)| name))
            .any(|name| !name.is_empty() && !PURE_BUILTINS.split_whitespace().any(|b| b == name));
        if calls_tracer || operand.contains('[') {
            let line = code[..i].matches('\n').count() + 1;
            found.push(format!("{part}:{line}: {}", operand.trim()));
        }
        i = start;
    }
    found
}

#[test]
fn no_call_or_index_stands_right_of_and_or() {
    let found: Vec<String> = build::TRACE_PARTS
        .iter()
        .flat_map(|(part, src)| unguarded_operands(part, src))
        .collect();
    assert!(
        found.is_empty(),
        "naga evaluates the right of && and || every time (gfx-rs/wgpu#4394); \
         write these guards as ifs:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_operand_check_catches_what_it_should() {
    let src = "bool f(uint i) {\n    return i < N && hit(buf[i]) > 0.0;\n}\n\
               bool g(float a) {\n    if (a > 0.0 || (x[0] == 1.0)) { return dot(v, v) > 0.0 && abs(a) < 1.0; }\n}\n\
               // a comment: ok && fine(x)\n";
    let found = unguarded_operands("t", src);
    assert_eq!(found.len(), 2, "{found:?}");
    assert!(found[0].starts_with("t:2: hit(buf[i]) > 0.0"), "{found:?}");
    assert!(found[1].starts_with("t:5: (x[0] == 1.0)"), "{found:?}");
}

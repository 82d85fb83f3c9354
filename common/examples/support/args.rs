//! The examples' command line: SCENE [KEY=VALUE] [ROUNDS], as
//! `cargo run --release -p twinray-common --example NAME -- teapot tessellation=160x120 5`
//! (an empty KEY=VALUE for none; three rounds by default).

pub struct Args {
    /// The scene's name, as `--scene` takes it.
    pub scene: String,
    /// The one `--set` given, as typed ("" for none), for the printed title.
    pub set: String,
    pub sets: Vec<(String, String)>,
    pub rounds: usize,
}

pub fn parse() -> Args {
    let a: Vec<String> = std::env::args().collect();
    let set = a.get(2).cloned().unwrap_or_default();
    let sets = match set.split_once('=') {
        Some((k, v)) => vec![(k.to_string(), v.to_string())],
        None if set.is_empty() => Vec::new(),
        None => panic!("'{set}': KEY=VALUE expected"),
    };
    Args {
        scene: a.get(1).cloned().expect("a scene name"),
        set,
        sets,
        rounds: a.get(3).map_or(3, |r| r.parse().expect("rounds")),
    }
}

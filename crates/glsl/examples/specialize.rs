//! `cargo run -p sunshade-glsl --example specialize -- IN.spv OUT.spv ID=VALUE...`: a module specialized for the
//! given spec-constant values (sunshade_glsl::specialize), with its instruction counts before and after.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: specialize IN.spv OUT.spv [ID=VALUE ...]");
        std::process::exit(2);
    }
    let bytes = std::fs::read(&args[0]).unwrap_or_else(|e| panic!("{}: {e}", args[0]));
    let words: Vec<u32> = bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    let constants: Vec<(u32, u32)> = args[2..]
        .iter()
        .map(|a| {
            let (k, v) = a.split_once('=').expect("ID=VALUE");
            (k.parse().expect("ID"), v.parse().expect("VALUE"))
        })
        .collect();
    let t = std::time::Instant::now();
    let out = sunshade_glsl::specialize(&words, &constants).unwrap_or_else(|e| panic!("{e}"));
    let elapsed = t.elapsed();
    let bytes: Vec<u8> = out.iter().flat_map(|w| w.to_le_bytes()).collect();
    std::fs::write(&args[1], bytes).unwrap_or_else(|e| panic!("{}: {e}", args[1]));
    println!(
        "{} -> {} instructions in {:.2} ms",
        sunshade_glsl::instruction_count(&words).unwrap(),
        sunshade_glsl::instruction_count(&out).unwrap(),
        elapsed.as_secs_f64() * 1e3
    );
}

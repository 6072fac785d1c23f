//! What a driver that inlines every call (lavapipe) is handed: a module's entry points with each call replaced by
//! its callee's body. [`inlined_instruction_count`] is the size a pipeline's creation on lavapipe grows with
//! (docs/platform.md, "What the driver compiles"); [`inlined_profile`] says which functions make it up, each
//! function's own instructions times the copies of its body that the entry points hold, so that a variant's
//! growth can be traced to the calls that cause it.

use std::collections::HashMap;

use crate::specialize::{
    instructions, literal_string, Inst, OP_ENTRY_POINT, OP_FUNCTION, OP_FUNCTION_CALL, OP_FUNCTION_END, OP_LINE,
    OP_NAME, OP_NO_LINE,
};

/// One function of a module as the inlining driver sees it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InlinedFunction {
    /// Its name as glslang writes it (`name(` and its parameters' types), or `%id` where the module names none.
    pub name: String,
    /// Its own instructions (its calls count one each; names and `OpLine`s none).
    pub own: usize,
    /// How many copies of its body the entry points hold once every call is inlined (1 for an entry point).
    pub copies: usize,
}

impl InlinedFunction {
    /// Its share of the inlined count: `own × copies`.
    pub fn inlined(&self) -> usize {
        self.own * self.copies
    }

    /// Its name without the parameters' types glslang appends (`atan_accurate` for `atan_accurate(f1;`).
    pub fn short_name(&self) -> &str {
        self.name.split('(').next().unwrap_or(&self.name)
    }
}

/// The instructions of a module's entry points' functions with every call replaced by the callee's body, as a driver
/// that inlines all calls first sees them: each function's own body counts once per call of it. Names, `OpLine`s
/// and the module's declarations do not count.
pub fn inlined_instruction_count(words: &[u32]) -> Result<usize, String> {
    Ok(inlined_profile(words)?.iter().map(InlinedFunction::inlined).sum())
}

/// Every function the entry points reach, with its own size and its copies once every call is inlined, largest
/// share ([`InlinedFunction::inlined`]) first. The shares sum to [`inlined_instruction_count`].
pub fn inlined_profile(words: &[u32]) -> Result<Vec<InlinedFunction>, String> {
    let insts = instructions(words)?;
    let bodies = function_bodies(&insts);
    // The call graph is acyclic (SPIR-V forbids recursion): copies flow from the entry points down in an order in
    // which every caller comes before its callees; a cycle is refused rather than followed.
    let entries: Vec<u32> = insts.iter().filter(|i| i.op == OP_ENTRY_POINT).map(|i| i.words[2]).collect();
    let order = callers_first(&entries, &bodies)?;
    let mut copies: HashMap<u32, usize> = HashMap::new();
    for &e in &entries {
        *copies.entry(e).or_default() += 1;
    }
    for f in &order {
        let n = copies.get(f).copied().unwrap_or(0);
        for callee in &bodies[f].1 {
            *copies.entry(*callee).or_default() += n;
        }
    }
    let names = function_names(&insts);
    let mut out: Vec<InlinedFunction> = order
        .iter()
        .map(|f| InlinedFunction {
            name: names.get(f).cloned().unwrap_or_else(|| format!("%{f}")),
            own: bodies[f].0,
            copies: copies[f],
        })
        .collect();
    out.sort_by(|a, b| b.inlined().cmp(&a.inlined()).then_with(|| a.name.cmp(&b.name)));
    Ok(out)
}

/// Each function's own instruction count and the functions it calls (once a call).
fn function_bodies(insts: &[Inst<'_>]) -> HashMap<u32, (usize, Vec<u32>)> {
    let mut bodies: HashMap<u32, (usize, Vec<u32>)> = HashMap::new();
    let mut current = None;
    for i in insts {
        match i.op {
            OP_FUNCTION => current = Some(i.words[2]),
            OP_FUNCTION_END => current = None,
            OP_NAME | OP_LINE | OP_NO_LINE => {}
            op => {
                if let Some(f) = current {
                    let entry = bodies.entry(f).or_default();
                    entry.0 += 1;
                    if op == OP_FUNCTION_CALL {
                        entry.1.push(i.words[3]);
                    }
                }
            }
        }
    }
    bodies
}

/// The functions reachable from `entries`, every caller before its callees (a reversed depth-first post-order).
fn callers_first(entries: &[u32], bodies: &HashMap<u32, (usize, Vec<u32>)>) -> Result<Vec<u32>, String> {
    // 1: on the current path, 2: done.
    let mut state: HashMap<u32, u8> = HashMap::new();
    let mut post = Vec::new();
    for &e in entries {
        if state.contains_key(&e) {
            continue;
        }
        // An explicit stack of (function, next callee to visit).
        let mut stack = vec![(e, 0usize)];
        state.insert(e, 1);
        while let Some((f, next)) = stack.last_mut() {
            let calls = &bodies.get(f).ok_or_else(|| format!("malformed SPIR-V: no function %{f}"))?.1;
            if let Some(&c) = calls.get(*next) {
                *next += 1;
                match state.get(&c) {
                    Some(1) => return Err(format!("malformed SPIR-V: function %{c} calls itself")),
                    Some(_) => {}
                    None => {
                        state.insert(c, 1);
                        stack.push((c, 0));
                    }
                }
            } else {
                let f = *f;
                state.insert(f, 2);
                post.push(f);
                stack.pop();
            }
        }
    }
    post.reverse();
    Ok(post)
}

/// `OpName`s of the functions.
fn function_names(insts: &[Inst<'_>]) -> HashMap<u32, String> {
    insts
        .iter()
        .filter(|i| i.op == OP_NAME && i.words.len() > 2)
        .map(|i| (i.words[1], literal_string(&i.words[2..]).0))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::specialize::{instruction_count, specialize};

    const SHADER: &str = r#"#version 460
layout(constant_id = 0) const uint MODE = 0u;
layout(location = 0) in vec4 v;
layout(location = 0) out vec4 o;
float heavy(float x) {
    float s = 0.0;
    for (int i = 0; i < 100; ++i) {
        s += sin(x * float(i));
    }
    return s;
}
float light(float x) {
    return x * 2.0;
}
float twice(float x) {
    return light(x) + light(x + 1.0);
}
void main() {
    float r;
    if (MODE == 1u) {
        r = heavy(v.x);
    } else {
        r = light(v.x);
    }
    if (MODE == 2u) {
        r += heavy(v.z) + twice(v.y) + twice(v.w);
    }
    o = vec4(r, 0.0, 0.0, 1.0);
}
"#;

    fn module(mode: u32) -> Vec<u32> {
        let words = crate::compile("t.frag", &[("t.frag", SHADER)], &[]).unwrap();
        specialize(&words, &[(0, mode)]).unwrap()
    }

    fn copies_of(profile: &[InlinedFunction], name: &str) -> usize {
        profile.iter().find(|f| f.short_name() == name).map_or(0, |f| f.copies)
    }

    #[test]
    fn the_inlined_count_takes_a_function_once_a_call() {
        let count = |w: &[u32]| inlined_instruction_count(w).unwrap();
        // MODE 0: light; 1: heavy; 2: light, and heavy, and light four times more through twice.
        let [light, heavy, both] = [0, 1, 2].map(module);
        assert!(count(&both) > count(&heavy) && count(&heavy) > count(&light));
        assert!(count(&light) < instruction_count(&light).unwrap());
        assert!(inlined_instruction_count(&[1, 2, 3]).is_err());
    }

    #[test]
    fn the_profile_counts_each_functions_copies_through_every_caller() {
        let profile = inlined_profile(&module(2)).unwrap();
        assert_eq!(copies_of(&profile, "main"), 1);
        assert_eq!(copies_of(&profile, "heavy"), 1);
        assert_eq!(copies_of(&profile, "twice"), 2);
        // Once from main, twice from each copy of twice.
        assert_eq!(copies_of(&profile, "light"), 5);
        let sum: usize = profile.iter().map(InlinedFunction::inlined).sum();
        assert_eq!(sum, inlined_instruction_count(&module(2)).unwrap());
        assert!(profile.windows(2).all(|w| w[0].inlined() >= w[1].inlined()));
        // What specialization removed is not in it.
        let light_only = inlined_profile(&module(0)).unwrap();
        assert_eq!((copies_of(&light_only, "heavy"), copies_of(&light_only, "light")), (0, 1));
    }
}

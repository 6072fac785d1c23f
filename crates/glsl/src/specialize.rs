//! Specializes a SPIR-V module for one set of specialization-constant values, removing the code those values make
//! unreachable, before a driver sees it.
//!
//! Why: lavapipe (Mesa 22.3 and 25.0) inlines every function a shader calls, reachable or not, before it folds the
//! specialization constants and drops dead branches. sunshade's fragment shader holds every light, BRDF, shadow
//! technique and material feature behind such constants, so each pipeline paid for all of them (docs/platform.md,
//! "What the driver compiles"). This pass does what the driver does later, earlier and only for integers and
//! booleans:
//!
//! 1. The spec constants take the given values (their defaults are rewritten, so the module stands alone), and every
//!    `OpSpecConstantOp` and every integer or boolean instruction whose operands are known is evaluated, as are
//!    `false && x`, `true || x` and a select of a known operand, and a load of a local that every store sets to
//!    one known value (glslang at -O0 keeps locals in memory: `bool cells = ONLY_SUN_CELL_RAYS || ...`).
//! 2. In each function, only the edges a known condition takes are followed from the entry block; a block that is
//!    reached no more keeps its label and becomes `OpUnreachable` (or, as a live loop's continue target, branches
//!    back to the header), so the structured control flow stays valid. A conditional branch with a known condition
//!    becomes an `OpBranch` (its `OpSelectionMerge` dropped), and phis keep the edges that remain.
//! 3. Functions that no live block calls are removed, with the names and decorations of everything removed.
//! 4. The fragment's stencil output (`FragStencilRefEXT`) where no live code writes it is removed, with the
//!    capability, extension and execution mode it needs: one module serves the pipelines that write it and those that do not, on
//!    devices with `VK_EXT_shader_stencil_export` and without (sunshade's first of two draws, gpu::second_draw).
//!
//! Floating-point instructions are never evaluated, reordered or rewritten: the code that remains is the
//! instructions the driver would have kept, word for word, so images are bitwise unchanged.

use std::collections::{HashMap, HashSet};

const OP_UNDEF: u16 = 1;
pub(crate) const OP_NAME: u16 = 5;
pub(crate) const OP_LINE: u16 = 8;
pub(crate) const OP_NO_LINE: u16 = 317;
const OP_DECORATE: u16 = 71;
const OP_DECORATE_ID: u16 = 332;
const OP_DECORATE_STRING: u16 = 5632;
const OP_TYPE_BOOL: u16 = 20;
const OP_TYPE_INT: u16 = 21;
const OP_CONSTANT_TRUE: u16 = 41;
const OP_CONSTANT_FALSE: u16 = 42;
const OP_CONSTANT: u16 = 43;
const OP_SPEC_CONSTANT_TRUE: u16 = 48;
const OP_SPEC_CONSTANT_FALSE: u16 = 49;
const OP_SPEC_CONSTANT: u16 = 50;
const OP_SPEC_CONSTANT_OP: u16 = 52;
pub(crate) const OP_FUNCTION: u16 = 54;
pub(crate) const OP_FUNCTION_END: u16 = 56;
pub(crate) const OP_FUNCTION_CALL: u16 = 57;
const OP_VARIABLE: u16 = 59;
const OP_LOAD: u16 = 61;
const OP_STORE: u16 = 62;
pub(crate) const OP_ENTRY_POINT: u16 = 15;
const OP_EXTENSION: u16 = 10;
const OP_CAPABILITY: u16 = 17;
const OP_EXECUTION_MODE: u16 = 16;
const EXECUTION_MODE_STENCIL_REF_REPLACING: u32 = 5027;
const OP_ACCESS_CHAIN: u16 = 65;
const DECORATION_BUILT_IN: u32 = 11;
const BUILT_IN_FRAG_STENCIL_REF: u32 = 5014;
const CAPABILITY_STENCIL_EXPORT: u32 = 5013;
const STENCIL_EXPORT_EXTENSION: &str = "SPV_EXT_shader_stencil_export";
const OP_PHI: u16 = 245;
const OP_LOOP_MERGE: u16 = 246;
const OP_SELECTION_MERGE: u16 = 247;
const OP_LABEL: u16 = 248;
const OP_BRANCH: u16 = 249;
const OP_BRANCH_CONDITIONAL: u16 = 250;
const OP_SWITCH: u16 = 251;
const OP_UNREACHABLE: u16 = 255;
const DECORATION_SPEC_ID: u32 = 1;

/// Opcodes that may appear in a function body without a result id (everything else there has its type at word 1 and
/// its result at word 2, but `OpLabel`, whose result is word 1).
const NO_RESULT: &[u16] = &[
    0,    // OpNop
    8,    // OpLine
    317,  // OpNoLine
    62,   // OpStore
    63,   // OpCopyMemory
    64,   // OpCopyMemorySized
    99,   // OpImageWrite
    218,  // OpEmitVertex
    219,  // OpEndPrimitive
    224,  // OpControlBarrier
    225,  // OpMemoryBarrier
    228,  // OpAtomicStore
    246,  // OpLoopMerge
    247,  // OpSelectionMerge
    249,  // OpBranch
    250,  // OpBranchConditional
    251,  // OpSwitch
    252,  // OpKill
    253,  // OpReturn
    254,  // OpReturnValue
    255,  // OpUnreachable
    256,  // OpLifetimeStart
    257,  // OpLifetimeStop
    4416, // OpTerminateInvocation
    4448, // OpIgnoreIntersectionKHR
    4449, // OpTerminateRayKHR
    4473, // OpRayQueryInitializeKHR
    4474, // OpRayQueryTerminateKHR
    4475, // OpRayQueryGenerateIntersectionKHR
    4476, // OpRayQueryConfirmIntersectionKHR
    5380, // OpDemoteToHelperInvocation
];

/// One instruction: its opcode and its words (the first word included).
#[derive(Clone, Copy)]
pub(crate) struct Inst<'a> {
    pub(crate) op: u16,
    pub(crate) words: &'a [u32],
}

pub(crate) fn instructions(words: &[u32]) -> Result<Vec<Inst<'_>>, String> {
    if words.len() < 5 || words[0] != 0x0723_0203 {
        return Err("not a SPIR-V module (magic number missing)".into());
    }
    instructions_from(words, 5)
}

/// The instructions of a stream of them without the module's header (a function's text).
fn instructions_of(words: &[u32]) -> Result<Vec<Inst<'_>>, String> {
    instructions_from(words, 0)
}

fn instructions_from(words: &[u32], first: usize) -> Result<Vec<Inst<'_>>, String> {
    let mut out = Vec::new();
    let mut at = first;
    while at < words.len() {
        let count = (words[at] >> 16) as usize;
        if count == 0 || at + count > words.len() {
            return Err(format!("malformed SPIR-V: instruction at word {at} runs past the end"));
        }
        out.push(Inst { op: (words[at] & 0xffff) as u16, words: &words[at..at + count] });
        at += count;
    }
    Ok(out)
}

/// The number of instructions in a SPIR-V module (what [`specialize`] leaves is measured with it).
pub fn instruction_count(words: &[u32]) -> Result<usize, String> {
    instructions(words).map(|v| v.len())
}

/// A function's block: where its instructions start (the `OpLabel`) and end (one past the terminator).
struct Block {
    label: u32,
    start: usize,
    end: usize,
}

struct Function {
    id: u32,
    /// Index of `OpFunction`, and one past `OpFunctionEnd`.
    start: usize,
    end: usize,
    blocks: Vec<Block>,
}

/// The result id an instruction in a function body defines, if any.
fn body_result(inst: Inst<'_>) -> Option<u32> {
    match inst.op {
        OP_LABEL => inst.words.get(1).copied(),
        op if NO_RESULT.contains(&op) => None,
        _ => inst.words.get(2).copied(),
    }
}

/// Evaluates an integer or boolean instruction whose operands are known (booleans as 0 or 1). `None` for anything
/// else, or where the result is not defined (division by zero, shifts by 32 or more).
fn evaluate(op: u16, a: &[u32]) -> Option<u32> {
    let b = |x: bool| Some(x as u32);
    let s = |x: u32| x as i32;
    match (op, a) {
        (128, [x, y]) => Some(x.wrapping_add(*y)),
        (130, [x, y]) => Some(x.wrapping_sub(*y)),
        (132, [x, y]) => Some(x.wrapping_mul(*y)),
        (134, [x, y]) => x.checked_div(*y),
        (137, [x, y]) => x.checked_rem(*y),
        (164, [x, y]) => b((*x != 0) == (*y != 0)),
        (165, [x, y]) => b((*x != 0) != (*y != 0)),
        (166, [x, y]) => b(*x != 0 || *y != 0),
        (167, [x, y]) => b(*x != 0 && *y != 0),
        (168, [x]) => b(*x == 0),
        (169, [c, x, y]) => Some(if *c != 0 { *x } else { *y }),
        (170, [x, y]) => b(x == y),
        (171, [x, y]) => b(x != y),
        (172, [x, y]) => b(x > y),
        (173, [x, y]) => b(s(*x) > s(*y)),
        (174, [x, y]) => b(x >= y),
        (175, [x, y]) => b(s(*x) >= s(*y)),
        (176, [x, y]) => b(x < y),
        (177, [x, y]) => b(s(*x) < s(*y)),
        (178, [x, y]) => b(x <= y),
        (179, [x, y]) => b(s(*x) <= s(*y)),
        (194, [x, y]) => x.checked_shr(*y),
        (196, [x, y]) => x.checked_shl(*y),
        (197, [x, y]) => Some(x | y),
        (198, [x, y]) => Some(x ^ y),
        (199, [x, y]) => Some(x & y),
        (200, [x]) => Some(!x),
        (83 | 400, [x]) => Some(*x),
        _ => None,
    }
}

/// [`evaluate`] where every operand is known; else the value that the known operands alone decide: `false && x`,
/// `true || x`, and a select whose condition and chosen operand are known (the instruction stays in the module for
/// the driver to compute; only the branches on it are decided here).
fn evaluate_partly(op: u16, a: &[Option<u32>]) -> Option<u32> {
    if let Some(all) = a.iter().copied().collect::<Option<Vec<u32>>>() {
        return evaluate(op, &all);
    }
    match (op, a) {
        (166, [x, y]) if *x == Some(1) || *y == Some(1) => Some(1),
        (167, [x, y]) if *x == Some(0) || *y == Some(0) => Some(0),
        (169, [Some(c), x, y]) => {
            if *c != 0 {
                *x
            } else {
                *y
            }
        }
        _ => None,
    }
}

/// What is known of a module under given constants: values, and each function's followed edges.
struct Analysis {
    known: HashMap<u32, u32>,
    /// (from, to) edges followed in live code.
    edges: HashSet<(u32, u32)>,
    reachable: HashSet<u32>,
    live_functions: HashSet<u32>,
}

/// The successors of a block's terminator, all of them (`None` for the condition: not known) or the one a known
/// condition takes.
fn successors(term: Inst<'_>, known: &HashMap<u32, u32>) -> Vec<u32> {
    let w = term.words;
    match term.op {
        OP_BRANCH => vec![w[1]],
        OP_BRANCH_CONDITIONAL => match known.get(&w[1]) {
            Some(&c) => vec![if c != 0 { w[2] } else { w[3] }],
            None => vec![w[2], w[3]],
        },
        OP_SWITCH => {
            // OpSwitch selector default (literal label)*: 32-bit selectors only (one word a literal).
            let pairs: Vec<(u32, u32)> = w[3..].chunks_exact(2).map(|p| (p[0], p[1])).collect();
            match known.get(&w[1]) {
                Some(&v) => vec![pairs.iter().find(|p| p.0 == v).map_or(w[2], |p| p.1)],
                None => std::iter::once(w[2]).chain(pairs.iter().map(|p| p.1)).collect(),
            }
        }
        _ => Vec::new(),
    }
}

/// Function-scope variables that only whole loads and stores touch (never handed to a call, an access chain or any
/// other instruction): what a load of one reads is what one of its stores wrote (or nothing, before the first).
/// glslang at -O0 keeps every local in such a variable, so a local set from a constant (`bool cells = ONLY_... ||
/// ...`) is known only through them.
fn plain_variables(insts: &[Inst<'_>], functions: &[Function]) -> HashSet<u32> {
    let bodies = || functions.iter().flat_map(|f| &insts[f.start..f.end]);
    let mut plain: HashSet<u32> = bodies().filter(|i| i.op == OP_VARIABLE).map(|i| i.words[2]).collect();
    for i in bodies() {
        // An OpLoad's operands past its pointer are memory-access literals; an OpStore's pointer and value are
        // what the variable holds and a value (never a pointer to a local in logical addressing).
        let operands = match i.op {
            OP_VARIABLE | OP_STORE => &[][..],
            OP_LOAD => &i.words[1..3],
            _ => &i.words[1..],
        };
        for w in operands {
            plain.remove(w);
        }
    }
    plain
}

fn analyse(
    insts: &[Inst<'_>],
    functions: &[Function],
    mut known: HashMap<u32, u32>,
    tracked: &HashSet<u32>,
) -> Analysis {
    let plain = plain_variables(insts, functions);
    let by_id: HashMap<u32, &Function> = functions.iter().map(|f| (f.id, f)).collect();
    let entry_points: Vec<u32> = insts.iter().filter(|i| i.op == OP_ENTRY_POINT).map(|i| i.words[2]).collect();
    // Each round first follows the edges the values known so far allow, then evaluates the reached blocks in the
    // function's order with those edges complete: a phi is known only where every edge that can still reach it
    // brings the same value. Knowing more only removes edges, so what is known stays true; the rounds stop when a
    // round learns nothing.
    loop {
        let before = known.len();
        let mut edges = HashSet::new();
        let mut reachable = HashSet::new();
        let mut live: HashSet<u32> = entry_points.iter().copied().collect();
        let mut queue: Vec<u32> = entry_points.clone();
        while let Some(fid) = queue.pop() {
            let Some(f) = by_id.get(&fid) else { continue };
            let index: HashMap<u32, &Block> = f.blocks.iter().map(|b| (b.label, b)).collect();
            let Some(first) = f.blocks.first() else { continue };
            let mut stack = vec![first.label];
            reachable.insert(first.label);
            while let Some(label) = stack.pop() {
                let Some(block) = index.get(&label) else { continue };
                for next in successors(insts[block.end - 1], &known) {
                    edges.insert((label, next));
                    if reachable.insert(next) {
                        stack.push(next);
                    }
                }
            }
            // Each plain variable's one value, where every store in a reached block writes the same known one.
            let mut stored: HashMap<u32, Option<u32>> = HashMap::new();
            for block in f.blocks.iter().filter(|b| reachable.contains(&b.label)) {
                for inst in insts[block.start..block.end].iter().filter(|i| i.op == OP_STORE) {
                    let (pointer, value) = (inst.words[1], known.get(&inst.words[2]).copied());
                    if plain.contains(&pointer) {
                        let one = stored.entry(pointer).or_insert(value);
                        if *one != value {
                            *one = None;
                        }
                    }
                }
            }
            for block in f.blocks.iter().filter(|b| reachable.contains(&b.label)) {
                for inst in &insts[block.start..block.end] {
                    let w = inst.words;
                    match inst.op {
                        OP_LOAD if tracked.contains(&w[1]) && !known.contains_key(&w[2]) => {
                            if let Some(Some(v)) = stored.get(&w[3]) {
                                known.insert(w[2], *v);
                            }
                        }
                        OP_FUNCTION_CALL if live.insert(w[3]) => queue.push(w[3]),
                        OP_PHI if tracked.contains(&w[1]) && !known.contains_key(&w[2]) => {
                            let values: Vec<Option<u32>> = w[3..]
                                .chunks_exact(2)
                                .filter(|p| edges.contains(&(p[1], block.label)))
                                .map(|p| known.get(&p[0]).copied())
                                .collect();
                            if let Some(Some(v)) = values.first() {
                                if values.iter().all(|x| *x == Some(*v)) {
                                    known.insert(w[2], *v);
                                }
                            }
                        }
                        OP_FUNCTION_CALL | OP_PHI => {}
                        op if w.len() >= 3 && tracked.contains(&w[1]) && !known.contains_key(&w[2]) => {
                            let args: Vec<Option<u32>> = w[3..].iter().map(|a| known.get(a).copied()).collect();
                            if let Some(v) = evaluate_partly(op, &args) {
                                known.insert(w[2], v);
                            }
                        }
                        _ => {}
                    }
                }
            }
        }
        if known.len() == before {
            return Analysis { known, edges, reachable, live_functions: live };
        }
    }
}

/// The literal string that starts at `words[0]` (nul-terminated, padded to whole words), and the words it takes.
pub(crate) fn literal_string(words: &[u32]) -> (String, usize) {
    let mut bytes = Vec::new();
    for (n, w) in words.iter().enumerate() {
        for b in w.to_le_bytes() {
            if b == 0 {
                return (String::from_utf8_lossy(&bytes).into_owned(), n + 1);
            }
            bytes.push(b);
        }
    }
    (String::from_utf8_lossy(&bytes).into_owned(), words.len())
}

/// The variable of the fragment's stencil output (decorated `BuiltIn FragStencilRefEXT`), where the module declares
/// one and no instruction of `body` (the live functions' text) stores to it, loads it or indexes it.
fn unwritten_stencil_output(header: &[Inst<'_>], body: &[u32]) -> Option<u32> {
    let var = header.iter().find_map(|i| {
        let w = i.words;
        (i.op == OP_DECORATE && w.len() >= 4 && w[2] == DECORATION_BUILT_IN && w[3] == BUILT_IN_FRAG_STENCIL_REF)
            .then(|| w[1])
    })?;
    let body = instructions_of(body).ok()?;
    let touched = body.iter().any(|i| match i.op {
        OP_STORE => i.words.get(1) == Some(&var),
        OP_LOAD | OP_ACCESS_CHAIN => i.words.get(3) == Some(&var),
        _ => false,
    });
    (!touched).then_some(var)
}

/// `words` specialized for `constants` (SpecId, value; booleans 0 or 1): see the module's documentation. Constants
/// the module does not declare are ignored; spec constants not named keep their defaults.
pub fn specialize(words: &[u32], constants: &[(u32, u32)]) -> Result<Vec<u32>, String> {
    let insts = instructions(words)?;
    let mut bound = words[3];
    // Spec ids, and the integer and boolean types whose values are tracked.
    let mut spec_ids: HashMap<u32, u32> = HashMap::new();
    let mut int_types = HashSet::new();
    let mut bool_types = HashSet::new();
    for i in &insts {
        let w = i.words;
        match i.op {
            OP_DECORATE if w.len() >= 4 && w[2] == DECORATION_SPEC_ID => {
                spec_ids.insert(w[1], w[3]);
            }
            OP_TYPE_INT if w.len() >= 3 && w[2] == 32 => {
                int_types.insert(w[1]);
            }
            OP_TYPE_BOOL => {
                bool_types.insert(w[1]);
            }
            _ => {}
        }
    }
    let tracked: HashSet<u32> = int_types.union(&bool_types).copied().collect();
    let value_of =
        |id: u32| spec_ids.get(&id).and_then(|sid| constants.iter().find(|(k, _)| k == sid)).map(|(_, v)| *v);
    // Global constants, spec constants (with their new values) and spec-constant operations, in order.
    let mut known: HashMap<u32, u32> = HashMap::new();
    let mut first_function = insts.len();
    for (n, i) in insts.iter().enumerate() {
        let w = i.words;
        match i.op {
            OP_FUNCTION => {
                first_function = n;
                break;
            }
            OP_CONSTANT_TRUE | OP_CONSTANT_FALSE if bool_types.contains(&w[1]) => {
                known.insert(w[2], (i.op == OP_CONSTANT_TRUE) as u32);
            }
            OP_SPEC_CONSTANT_TRUE | OP_SPEC_CONSTANT_FALSE if bool_types.contains(&w[1]) => {
                let default = (i.op == OP_SPEC_CONSTANT_TRUE) as u32;
                known.insert(w[2], value_of(w[2]).map_or(default, |v| (v != 0) as u32));
            }
            OP_CONSTANT | OP_SPEC_CONSTANT if int_types.contains(&w[1]) && w.len() == 4 => {
                let v = if i.op == OP_SPEC_CONSTANT { value_of(w[2]).unwrap_or(w[3]) } else { w[3] };
                known.insert(w[2], v);
            }
            OP_SPEC_CONSTANT_OP if tracked.contains(&w[1]) => {
                let args: Option<Vec<u32>> = w[4..].iter().map(|a| known.get(a).copied()).collect();
                if let Some(v) = args.and_then(|a| evaluate(w[3] as u16, &a)) {
                    known.insert(w[2], v);
                }
            }
            _ => {}
        }
    }
    // Functions and their blocks.
    let mut functions = Vec::new();
    let mut n = first_function;
    while n < insts.len() {
        if insts[n].op != OP_FUNCTION {
            return Err(format!("malformed SPIR-V: instruction {n} (opcode {}) outside a function", insts[n].op));
        }
        let id = insts[n].words[2];
        let start = n;
        let mut blocks = Vec::new();
        while n < insts.len() && insts[n].op != OP_FUNCTION_END {
            if insts[n].op == OP_LABEL {
                let label = insts[n].words[1];
                let block_start = n;
                while n < insts.len() && !is_terminator(insts[n].op) && insts[n].op != OP_FUNCTION_END {
                    n += 1;
                }
                if n == insts.len() || insts[n].op == OP_FUNCTION_END {
                    return Err("malformed SPIR-V: a block without a terminator".into());
                }
                blocks.push(Block { label, start: block_start, end: n + 1 });
            }
            n += 1;
        }
        if n == insts.len() {
            return Err("malformed SPIR-V: a function without OpFunctionEnd".into());
        }
        n += 1;
        functions.push(Function { id, start, end: n, blocks });
    }
    let a = analyse(&insts, &functions, known, &tracked);

    // Loops whose header is live: their continue targets, branching back, stay even where unreached.
    let mut continue_of: HashMap<u32, u32> = HashMap::new();
    for f in &functions {
        for b in &f.blocks {
            if !a.reachable.contains(&b.label) {
                continue;
            }
            for i in &insts[b.start..b.end] {
                if i.op == OP_LOOP_MERGE {
                    continue_of.insert(i.words[2], b.label);
                }
            }
        }
    }
    // Back edges from unreached continue targets stay in the CFG, so their headers' phis keep that edge: with an
    // OpUndef where the value was defined in removed code.
    let back_edges: HashSet<(u32, u32)> =
        continue_of.iter().filter(|(c, _)| !a.reachable.contains(c)).map(|(c, h)| (*c, *h)).collect();

    // The functions' new text, and the ids it defines.
    let mut body: Vec<u32> = Vec::new();
    let mut defined: HashSet<u32> = HashSet::new();
    let mut undefs: HashMap<u32, u32> = HashMap::new(); // type -> OpUndef id
    for f in functions.iter().filter(|f| a.live_functions.contains(&f.id)) {
        let first_block = f.blocks.first().map_or(f.end - 1, |b| b.start);
        for i in &insts[f.start..first_block] {
            body.extend_from_slice(i.words);
            defined.extend(body_result(*i));
        }
        defined.insert(f.id);
        for b in &f.blocks {
            if !a.reachable.contains(&b.label) {
                body.extend_from_slice(&[(2 << 16) | OP_LABEL as u32, b.label]);
                defined.insert(b.label);
                match continue_of.get(&b.label) {
                    Some(&header) => body.extend_from_slice(&[(2 << 16) | OP_BRANCH as u32, header]),
                    None => body.push((1 << 16) | OP_UNREACHABLE as u32),
                }
                continue;
            }
            let block = &insts[b.start..b.end];
            let term = block[block.len() - 1];
            let taken = successors(term, &a.known);
            let folded = matches!(term.op, OP_BRANCH_CONDITIONAL | OP_SWITCH) && taken.len() == 1;
            for (k, i) in block.iter().enumerate() {
                let w = i.words;
                if i.op == OP_PHI {
                    let mut kept = vec![0, w[1], w[2]];
                    for p in w[3..].chunks_exact(2) {
                        if a.edges.contains(&(p[1], b.label)) {
                            kept.extend_from_slice(p);
                        } else if back_edges.contains(&(p[1], b.label)) {
                            let undef = *undefs.entry(w[1]).or_insert_with(|| {
                                bound += 1;
                                bound - 1
                            });
                            kept.extend_from_slice(&[undef, p[1]]);
                        }
                    }
                    kept[0] = ((kept.len() as u32) << 16) | OP_PHI as u32;
                    body.extend_from_slice(&kept);
                    defined.insert(w[2]);
                    continue;
                }
                if folded && i.op == OP_SELECTION_MERGE && k + 2 == block.len() {
                    continue;
                }
                if folded && k + 1 == block.len() {
                    body.extend_from_slice(&[(2 << 16) | OP_BRANCH as u32, taken[0]]);
                    continue;
                }
                body.extend_from_slice(w);
                defined.extend(body_result(*i));
            }
        }
        body.extend_from_slice(insts[f.end - 1].words);
    }

    // The module before its functions, less the names and decorations of what was removed, with the spec
    // constants' new defaults and the OpUndefs the phis need.
    let mut out: Vec<u32> = words[..5].to_vec();
    // Types, strings and imports define the id at word 1; constants and global variables at word 2 (after their
    // type); debug, annotation and mode-setting instructions only name ids.
    const NAMING: &[u16] = &[2, 3, 4, 5, 6, 8, 10, 14, 15, 16, 17, 71, 72, 74, 317, 330, 331, 332, 5632, 5633];
    for i in insts[..first_function].iter().filter(|i| !NAMING.contains(&i.op)) {
        let at = if matches!(i.op, 7 | 11 | 19..=39 | 73 | 322 | 4472 | 5341) { 1 } else { 2 };
        defined.extend(i.words.get(at));
    }
    // Step 4: the stencil output no live code writes, with what only it needs.
    let unwritten = unwritten_stencil_output(&insts[..first_function], &body);
    if let Some(var) = unwritten {
        defined.remove(&var);
    }
    for i in &insts[..first_function] {
        let w = i.words;
        match i.op {
            OP_NAME | OP_DECORATE | OP_DECORATE_ID | OP_DECORATE_STRING if !defined.contains(&w[1]) => continue,
            OP_VARIABLE if unwritten == w.get(2).copied() => continue,
            OP_CAPABILITY if unwritten.is_some() && w.get(1) == Some(&CAPABILITY_STENCIL_EXPORT) => continue,
            OP_EXECUTION_MODE if unwritten.is_some() && w.get(2) == Some(&EXECUTION_MODE_STENCIL_REF_REPLACING) => {
                continue
            }
            OP_EXTENSION if unwritten.is_some() && literal_string(&w[1..]).0 == STENCIL_EXPORT_EXTENSION => continue,
            OP_ENTRY_POINT if unwritten.is_some() => {
                // Execution model, function, name, then the interface's ids.
                let interface = 3 + literal_string(&w[3..]).1;
                let mut kept: Vec<u32> = w[..interface.min(w.len())].to_vec();
                kept.extend(w.iter().skip(interface).filter(|id| Some(**id) != unwritten));
                kept[0] = ((kept.len() as u32) << 16) | OP_ENTRY_POINT as u32;
                out.extend_from_slice(&kept);
                continue;
            }
            OP_SPEC_CONSTANT if w.len() == 4 => {
                let v = value_of(w[2]).unwrap_or(w[3]);
                out.extend_from_slice(&[w[0], w[1], w[2], v]);
                continue;
            }
            OP_SPEC_CONSTANT_TRUE | OP_SPEC_CONSTANT_FALSE => {
                let default = i.op == OP_SPEC_CONSTANT_TRUE;
                let v = value_of(w[2]).map_or(default, |v| v != 0);
                let op = if v { OP_SPEC_CONSTANT_TRUE } else { OP_SPEC_CONSTANT_FALSE };
                out.extend_from_slice(&[(w[0] & 0xffff_0000) | op as u32, w[1], w[2]]);
                continue;
            }
            _ => out.extend_from_slice(w),
        }
    }
    let mut undefs: Vec<(u32, u32)> = undefs.into_iter().collect();
    undefs.sort();
    for (ty, id) in undefs {
        out.extend_from_slice(&[(3 << 16) | OP_UNDEF as u32, ty, id]);
    }
    out.extend_from_slice(&body);
    out[3] = bound;
    Ok(out)
}

fn is_terminator(op: u16) -> bool {
    matches!(op, OP_BRANCH | OP_BRANCH_CONDITIONAL | OP_SWITCH | 252 | 253 | 254 | OP_UNREACHABLE | 4416 | 4448 | 4449)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SHADER: &str = r#"#version 460
layout(constant_id = 0) const uint MODE = 0u;
layout(constant_id = 1) const bool FLAG = false;
const bool TWO = MODE == 2u;
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
float flagged(float x) {
    return x + 1.0;
}
float ored(float x) {
    return x - 1.0;
}
void main() {
    float r;
    if (MODE == 1u) {
        r = heavy(v.x);
    } else {
        r = light(v.x);
    }
    for (uint i = 0u; TWO && i < uint(v.y); ++i) {
        r += heavy(v.z);
    }
    if (FLAG && v.w > 0.0) {
        r = flagged(r);
    }
    // A phi of a known and an unknown value: not known.
    if (v.w > 0.0 || MODE == 3u) {
        r = ored(r);
    }
    o = vec4(r, 0.0, 0.0, 1.0);
}
"#;

    fn module() -> Vec<u32> {
        crate::compile("t.frag", &[("t.frag", SHADER)], &[]).unwrap()
    }

    /// The names of the functions a module defines (glslang names them `name(args;`).
    fn functions(words: &[u32]) -> Vec<String> {
        let insts = instructions(words).unwrap();
        let defined: HashSet<u32> = insts.iter().filter(|i| i.op == OP_FUNCTION).map(|i| i.words[2]).collect();
        insts
            .iter()
            .filter(|i| i.op == OP_NAME && defined.contains(&i.words[1]))
            .map(|i| {
                let bytes: Vec<u8> = i.words[2..].iter().flat_map(|w| w.to_le_bytes()).collect();
                let s = String::from_utf8_lossy(&bytes).trim_end_matches('\0').to_string();
                s.split('(').next().unwrap().to_string()
            })
            .collect()
    }

    fn spirv_val(words: &[u32]) {
        crate::spirv_val(words).unwrap_or_else(|e| panic!("{e}"));
    }

    #[test]
    fn each_value_keeps_only_the_functions_it_calls() {
        let words = module();
        spirv_val(&words);
        let mut all = functions(&words);
        all.sort();
        assert_eq!(all, ["flagged", "heavy", "light", "main", "ored"]);
        for (constants, expected) in [
            (&[(0, 0), (1, 0)][..], &["light", "main", "ored"][..]),
            (&[(0, 1), (1, 0)], &["heavy", "main", "ored"]),
            (&[(0, 2), (1, 0)], &["heavy", "light", "main", "ored"]),
            (&[(0, 0), (1, 1)], &["flagged", "light", "main", "ored"]),
            (&[(0, 3), (1, 1)], &["flagged", "light", "main", "ored"]),
        ] {
            let out = specialize(&words, constants).unwrap();
            spirv_val(&out);
            let mut kept = functions(&out);
            kept.sort();
            assert_eq!(kept, expected, "{constants:?}");
            assert!(instruction_count(&out).unwrap() < instruction_count(&words).unwrap());
            // Specializing again changes nothing: every branch left depends on run-time values.
            assert_eq!(specialize(&out, constants).unwrap(), out, "{constants:?}");
        }
    }

    /// Locals set from constants, a constant and-ed with a run-time value, and a local a call may change.
    const LOCALS: &str = r#"#version 450
layout(constant_id = 0) const uint MODE = 0u;
const bool ON = MODE == 1u;
layout(location = 0) in vec4 v;
layout(location = 0) out vec4 o;
float local_set(float x) {
    return sin(x) * cos(x);
}
float anded(float x) {
    return x * 3.0;
}
float escaped(float x) {
    return x + 2.0;
}
void maybe_set(inout bool b) {
    if (v.x > 0.0) {
        b = true;
    }
}
void main() {
    float r = v.x;
    bool local = MODE == 1u;
    if (local) {
        r = local_set(r);
    }
    bool both = ON && v.z > 0.0;
    if (both) {
        r = anded(r);
    }
    bool handed = MODE == 1u;
    maybe_set(handed);
    if (handed) {
        r = escaped(r);
    }
    o = vec4(r);
}
"#;

    #[test]
    fn locals_and_logical_operations_that_constants_decide_are_known() {
        let words = crate::compile("l.frag", &[("l.frag", LOCALS)], &[]).unwrap();
        for (mode, expected) in
            [(0, &["escaped", "main", "maybe_set"][..]), (1, &["anded", "escaped", "local_set", "main", "maybe_set"])]
        {
            let out = specialize(&words, &[(0, mode)]).unwrap();
            spirv_val(&out);
            let mut kept = functions(&out);
            kept.sort();
            assert_eq!(kept, expected, "MODE = {mode}");
        }
        assert_eq!(evaluate_partly(167, &[None, Some(0)]), Some(0));
        assert_eq!(evaluate_partly(167, &[None, Some(1)]), None);
        assert_eq!(evaluate_partly(166, &[Some(1), None]), Some(1));
        assert_eq!(evaluate_partly(169, &[Some(0), None, Some(4)]), Some(4));
        assert_eq!(evaluate_partly(169, &[Some(1), None, Some(4)]), None);
        assert_eq!(evaluate_partly(170, &[None, Some(4)]), None);
    }

    #[test]
    fn the_values_are_written_into_the_module() {
        let out = specialize(&module(), &[(0, 7), (1, 1)]).unwrap();
        let insts = instructions(&out).unwrap();
        let spec: Vec<(u16, u32)> = insts
            .iter()
            .filter(|i| matches!(i.op, OP_SPEC_CONSTANT | OP_SPEC_CONSTANT_TRUE | OP_SPEC_CONSTANT_FALSE))
            .map(|i| (i.op, i.words.get(3).copied().unwrap_or(0)))
            .collect();
        assert_eq!(spec, [(OP_SPEC_CONSTANT, 7), (OP_SPEC_CONSTANT_TRUE, 0)]);
    }

    #[test]
    fn constants_it_does_not_declare_are_ignored_and_bad_input_is_an_error() {
        let words = module();
        assert_eq!(specialize(&words, &[(9, 1)]).unwrap(), specialize(&words, &[]).unwrap());
        assert!(specialize(&[1, 2, 3], &[]).unwrap_err().contains("not a SPIR-V module"));
        let mut truncated = words.clone();
        truncated.truncate(words.len() - 1);
        assert!(specialize(&truncated, &[]).is_err());
    }

    #[test]
    fn integer_and_boolean_instructions_evaluate_as_the_device_does() {
        assert_eq!(evaluate(170, &[3, 3]), Some(1));
        assert_eq!(evaluate(199, &[0b1011, 0b0110]), Some(0b0010));
        assert_eq!(evaluate(177, &[u32::MAX, 0]), Some(1)); // -1 < 0 signed
        assert_eq!(evaluate(176, &[u32::MAX, 0]), Some(0)); // unsigned
        assert_eq!(evaluate(134, &[1, 0]), None);
        assert_eq!(evaluate(196, &[1, 32]), None);
        assert_eq!(evaluate(169, &[0, 5, 6]), Some(6));
        // Floating-point instructions are never evaluated.
        assert_eq!(evaluate(129, &[0x3f80_0000, 0x3f80_0000]), None);
    }

    /// A stencil output written only under a constant: kept with its capability and extension where the constant
    /// selects the write, gone (output, capability, extension, entry point's interface) where it does not, so that
    /// the module is valid for a device without the extension.
    #[test]
    fn an_unwritten_stencil_output_goes_with_its_capability() {
        let shader = r#"#version 460
#extension GL_ARB_shader_stencil_export : require
layout(constant_id = 0) const uint MARK = 0u;
layout(location = 0) in vec4 v;
layout(location = 0) out vec4 o;
void main() {
    if (MARK == 1u) {
        gl_FragStencilRefARB = v.x > 0.0 ? 1 : 0;
    }
    o = v;
}
"#;
        let words = crate::compile("s.frag", &[("s.frag", shader)], &[]).unwrap();
        let has = |words: &[u32], op: u16, operand: u32| {
            instructions(words).unwrap().iter().any(|i| i.op == op && i.words.get(1) == Some(&operand))
        };
        let extension = |words: &[u32]| {
            instructions(words)
                .unwrap()
                .iter()
                .any(|i| i.op == OP_EXTENSION && literal_string(&i.words[1..]).0 == STENCIL_EXPORT_EXTENSION)
        };
        let stencil_var = |words: &[u32]| {
            instructions(words).unwrap().iter().find_map(|i| {
                let w = i.words;
                (i.op == OP_DECORATE
                    && w.len() >= 4
                    && w[2] == DECORATION_BUILT_IN
                    && w[3] == BUILT_IN_FRAG_STENCIL_REF)
                    .then(|| w[1])
            })
        };
        assert!(has(&words, OP_CAPABILITY, CAPABILITY_STENCIL_EXPORT) && extension(&words));
        let written = specialize(&words, &[(0, 1)]).unwrap();
        spirv_val(&written);
        assert!(has(&written, OP_CAPABILITY, CAPABILITY_STENCIL_EXPORT) && extension(&written));
        assert!(stencil_var(&written).is_some());
        let unwritten = specialize(&words, &[(0, 0)]).unwrap();
        spirv_val(&unwritten);
        assert!(!has(&unwritten, OP_CAPABILITY, CAPABILITY_STENCIL_EXPORT) && !extension(&unwritten));
        let var = stencil_var(&words).unwrap();
        assert!(stencil_var(&unwritten).is_none());
        let names_var = |i: &Inst<'_>| {
            matches!(i.op, OP_NAME | OP_DECORATE | OP_VARIABLE) && i.words[1..].iter().take(2).any(|w| *w == var)
        };
        assert!(!instructions(&unwritten).unwrap().iter().any(names_var));
        // The other output and the input stay in the entry point's interface.
        let entry = instructions(&unwritten).unwrap().into_iter().find(|i| i.op == OP_ENTRY_POINT).unwrap();
        assert_eq!(entry.words.len() - 3 - literal_string(&entry.words[3..]).1, 2);
    }
}

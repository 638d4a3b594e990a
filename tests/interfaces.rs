//! The host↔GLSL contracts, checked against the committed SPIR-V: every kernel and shader stage
//! is reflected, and its descriptor sets, descriptor types and counts, push-constant block,
//! buffer structs and vertex inputs are compared with the Rust side's [`Interface`] for it,
//! member by member (names and offsets). The Rust types' own layouts are asserted at compile
//! time ([`lookdev::glsl_struct!`]); this closes the loop with the GLSL.

mod common;

use ash::vk;
use lookdev::gpu::{shaders, BindingKind, GlslStruct, Interface};
use rspirv::binary::{Consumer, ParseAction};
use rspirv::dr::{Instruction, ModuleHeader, Operand};
use rspirv::spirv::{Decoration, Op, StorageClass};
use std::collections::{BTreeMap, HashMap};

/// Every module's interface, as the renderer, the bake and the test probes build them.
fn interfaces() -> Vec<Interface> {
    let mut all = vec![
        lookdev::render::passes::resolve::INTERFACE,
        lookdev::render::passes::relight::INTERFACE,
        lookdev::render::passes::finalize::INTERFACE,
        lookdev::render::passes::denoise::INTERFACE,
        lookdev::render::energy::INTERFACE,
        common::probes::BRDF_PROBE,
        common::probes::SAMPLE_PROBE,
    ];
    all.extend(lookdev::asset::bake::INTERFACES);
    all
}

/// Collects a module's instructions as they are parsed, in order.
#[derive(Default)]
struct Instructions(Vec<Instruction>);

impl Consumer for Instructions {
    fn initialize(&mut self) -> ParseAction {
        ParseAction::Continue
    }
    fn finalize(&mut self) -> ParseAction {
        ParseAction::Continue
    }
    fn consume_header(&mut self, _: ModuleHeader) -> ParseAction {
        ParseAction::Continue
    }
    fn consume_instruction(&mut self, instruction: Instruction) -> ParseAction {
        self.0.push(instruction);
        ParseAction::Continue
    }
}

/// A SPIR-V module's types, variables, names and decorations, by id.
struct Spirv {
    names: HashMap<u32, String>,
    member_names: HashMap<(u32, u32), String>,
    member_offsets: HashMap<(u32, u32), u32>,
    decorations: HashMap<(u32, Decoration), u32>,
    definitions: HashMap<u32, Instruction>,
    /// Global variables: (id, storage class, the type they point at).
    variables: Vec<(u32, StorageClass, u32)>,
}

fn id(operand: &Operand) -> u32 {
    match operand {
        Operand::IdRef(id) => *id,
        other => panic!("expected an id, found {other:?}"),
    }
}

fn literal(operand: &Operand) -> u32 {
    match operand {
        Operand::LiteralBit32(value) => *value,
        other => panic!("expected a literal, found {other:?}"),
    }
}

impl Spirv {
    fn parse(bytes: &[u8]) -> Spirv {
        let mut instructions = Instructions::default();
        rspirv::binary::parse_bytes(bytes, &mut instructions).expect("the committed SPIR-V parses");
        let mut spirv = Spirv {
            names: HashMap::new(),
            member_names: HashMap::new(),
            member_offsets: HashMap::new(),
            decorations: HashMap::new(),
            definitions: HashMap::new(),
            variables: Vec::new(),
        };
        for instruction in instructions.0 {
            match (instruction.class.opcode, &instruction.operands[..]) {
                (Op::Name, [target, Operand::LiteralString(text)]) => {
                    spirv.names.insert(id(target), text.clone());
                }
                (Op::MemberName, [target, member, Operand::LiteralString(text)]) => {
                    spirv.member_names.insert((id(target), literal(member)), text.clone());
                }
                (Op::MemberDecorate, [target, member, Operand::Decoration(Decoration::Offset), offset]) => {
                    spirv.member_offsets.insert((id(target), literal(member)), literal(offset));
                }
                (Op::Decorate, [target, Operand::Decoration(decoration), Operand::LiteralBit32(value), ..]) => {
                    spirv.decorations.insert((id(target), *decoration), *value);
                }
                (Op::Decorate, [target, Operand::Decoration(decoration)]) => {
                    spirv.decorations.insert((id(target), *decoration), 0);
                }
                _ => {}
            }
            // Only module-level variables come before the first function.
            if instruction.class.opcode == Op::Function {
                break;
            }
            if let (Op::Variable, Some(result), Some(pointer), [Operand::StorageClass(class), ..]) =
                (instruction.class.opcode, instruction.result_id, instruction.result_type, &instruction.operands[..])
            {
                let pointee = id(&spirv.definition(pointer).operands[1]);
                spirv.variables.push((result, *class, pointee));
            }
            if let Some(result) = instruction.result_id {
                spirv.definitions.insert(result, instruction);
            }
        }
        spirv
    }

    fn definition(&self, id: u32) -> &Instruction {
        &self.definitions[&id]
    }

    fn name(&self, id: u32) -> String {
        self.names.get(&id).cloned().unwrap_or_default()
    }

    /// The descriptors the module declares: (set, binding) → (type, count, name).
    fn descriptors(&self) -> BTreeMap<(u32, u32), (vk::DescriptorType, u32, String)> {
        let mut descriptors = BTreeMap::new();
        for &(variable, class, pointee) in &self.variables {
            let (Some(&set), Some(&binding)) = (
                self.decorations.get(&(variable, Decoration::DescriptorSet)),
                self.decorations.get(&(variable, Decoration::Binding)),
            ) else {
                continue;
            };
            let (element, count) = match self.definition(pointee).class.opcode {
                Op::TypeArray => {
                    let def = self.definition(pointee);
                    (id(&def.operands[0]), self.constant(id(&def.operands[1])))
                }
                _ => (pointee, 1),
            };
            let def = self.definition(element);
            let ty = match def.class.opcode {
                Op::TypeSampledImage => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                Op::TypeSampler => vk::DescriptorType::SAMPLER,
                // The "sampled" operand: 2 for an image read and written without a sampler.
                Op::TypeImage if literal(&def.operands[5]) == 2 => vk::DescriptorType::STORAGE_IMAGE,
                Op::TypeImage => vk::DescriptorType::SAMPLED_IMAGE,
                Op::TypeStruct if class == StorageClass::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
                Op::TypeStruct if self.decorations.contains_key(&(element, Decoration::BufferBlock)) => {
                    vk::DescriptorType::STORAGE_BUFFER
                }
                Op::TypeStruct => vk::DescriptorType::UNIFORM_BUFFER,
                other => panic!("{}: no descriptor type for {other:?}", self.name(variable)),
            };
            let name = match self.name(variable) {
                name if name.is_empty() => self.name(element),
                name => name,
            };
            descriptors.insert((set, binding), (ty, count, name));
        }
        descriptors
    }

    fn constant(&self, id: u32) -> u32 {
        let def = self.definition(id);
        assert_eq!(def.class.opcode, Op::Constant, "an array length is a constant");
        literal(&def.operands[0])
    }

    /// The structs named `name` that have an explicit layout (members with offsets): a struct
    /// used only in functions has none.
    fn laid_out_structs(&self, name: &str) -> Vec<u32> {
        let mut found: Vec<u32> = self
            .definitions
            .values()
            .filter(|i| i.class.opcode == Op::TypeStruct)
            .map(|i| i.result_id.unwrap())
            .filter(|&id| self.name(id) == name && self.member_offsets.contains_key(&(id, 0)))
            .collect();
        found.sort();
        found
    }

    /// A struct's members: (name, offset).
    fn members(&self, struct_id: u32) -> Vec<(String, u32)> {
        let count = self.definition(struct_id).operands.len() as u32;
        (0..count)
            .map(|m| {
                let name = self.member_names.get(&(struct_id, m)).cloned().unwrap_or_default();
                (name, self.member_offsets[&(struct_id, m)])
            })
            .collect()
    }

    /// The bytes a type takes in an explicitly laid-out block (to its last member's end, for a
    /// struct).
    fn size(&self, type_id: u32) -> u32 {
        let def = self.definition(type_id);
        match def.class.opcode {
            Op::TypeInt | Op::TypeFloat => literal(&def.operands[0]) / 8,
            Op::TypeVector | Op::TypeMatrix => self.size(id(&def.operands[0])) * literal(&def.operands[1]),
            Op::TypeArray => {
                self.decorations[&(type_id, Decoration::ArrayStride)] * self.constant(id(&def.operands[1]))
            }
            Op::TypeRuntimeArray => 0,
            Op::TypeStruct => {
                let last = def.operands.len() - 1;
                self.member_offsets[&(type_id, last as u32)] + self.size(id(&def.operands[last]))
            }
            other => panic!("no size for {other:?}"),
        }
    }

    /// The strides of the arrays (sized or not) whose elements are `struct_id`.
    fn array_strides(&self, struct_id: u32) -> Vec<u32> {
        self.definitions
            .values()
            .filter(|i| matches!(i.class.opcode, Op::TypeArray | Op::TypeRuntimeArray))
            .filter(|i| id(&i.operands[0]) == struct_id)
            .filter_map(|i| self.decorations.get(&(i.result_id.unwrap(), Decoration::ArrayStride)).copied())
            .collect()
    }

    /// The variables of a storage class, with the types they point at.
    fn variables(&self, class: StorageClass) -> Vec<(u32, u32)> {
        self.variables.iter().filter(|v| v.1 == class).map(|&(id, _, pointee)| (id, pointee)).collect()
    }

    /// The components of a scalar or vector type.
    fn components(&self, type_id: u32) -> u32 {
        let def = self.definition(type_id);
        match def.class.opcode {
            Op::TypeVector => literal(&def.operands[1]),
            _ => 1,
        }
    }
}

/// Compares a Rust struct's members with the SPIR-V struct's: every GLSL member must be in the
/// Rust type at the same offset, and the Rust type may add only padding (`pad…`) beyond them.
fn compare_members(rust: &GlslStruct, spirv: &Spirv, struct_id: u32, problems: &mut Vec<String>) {
    let glsl = spirv.members(struct_id);
    for (name, offset) in &glsl {
        match rust.members.iter().find(|(n, _)| n == name) {
            Some(&(_, rust_offset)) if rust_offset as u32 == *offset => {}
            Some(&(_, rust_offset)) => problems.push(format!(
                "{}.{name}: the GLSL has it at byte {offset}, the Rust type at {rust_offset}",
                rust.name
            )),
            None => problems.push(format!("{}.{name} (byte {offset}) is missing from the Rust type", rust.name)),
        }
    }
    for (name, _) in rust.members {
        if !name.starts_with("pad") && !glsl.iter().any(|(n, _)| n == name) {
            problems.push(format!("{}.{name} is in the Rust type but not in the GLSL", rust.name));
        }
    }
    let glsl_size = spirv.size(struct_id) as usize;
    if rust.size < glsl_size {
        problems.push(format!("{}: the Rust type has {} bytes, the GLSL {glsl_size}", rust.name, rust.size));
    }
    for stride in spirv.array_strides(struct_id) {
        if stride as usize != rust.size {
            problems
                .push(format!("{}: arrays of it step {stride} bytes, the Rust type is {} bytes", rust.name, rust.size));
        }
    }
}

/// The component count of a vertex attribute format.
fn format_components(format: vk::Format) -> u32 {
    use vk::Format;
    match format {
        Format::R32_SFLOAT | Format::R32_UINT => 1,
        Format::R32G32_SFLOAT => 2,
        Format::R32G32B32_SFLOAT => 3,
        Format::R32G32B32A32_SFLOAT => 4,
        other => panic!("no component count for {other:?}"),
    }
}

/// What differs between `interface` and its committed SPIR-V.
fn check(interface: &Interface) -> Vec<String> {
    let spirv = Spirv::parse(interface.spirv);
    let mut problems = Vec::new();

    // Descriptor sets: each binding the module declares, as the Rust side binds it.
    let descriptors = spirv.descriptors();
    for (&(set, binding), (ty, count, name)) in &descriptors {
        let Some(kind) = interface.sets.get(set as usize).and_then(|s| s.get(binding as usize)) else {
            problems.push(format!("set {set} binding {binding} ({name}) has no Rust binding"));
            continue;
        };
        if *ty != kind.descriptor_type() {
            problems.push(format!("set {set} binding {binding} ({name}): the GLSL has {ty:?}, Rust {kind:?}"));
        }
        if *count != kind.count() {
            problems.push(format!("set {set} binding {binding} ({name}): {count} descriptors, Rust {}", kind.count()));
        }
    }
    // A kernel is the whole pipeline: the Rust side binds nothing it does not declare.
    if interface.file.ends_with(".comp") {
        for (set, kinds) in interface.sets.iter().enumerate() {
            for binding in 0..kinds.len() as u32 {
                if !descriptors.contains_key(&(set as u32, binding)) {
                    problems.push(format!("set {set} binding {binding} is bound by Rust but not declared"));
                }
            }
        }
    }

    // The push-constant block.
    let push = spirv.variables(StorageClass::PushConstant);
    match (interface.push, push.as_slice()) {
        (None, []) => {}
        (Some(rust), [(_, block)]) => {
            if spirv.name(*block) != rust.name {
                problems.push(format!("the push-constant block is {:?}, not {}", spirv.name(*block), rust.name));
            }
            let size = spirv.size(*block) as usize;
            if size != rust.size {
                problems.push(format!("push constants: the GLSL has {size} bytes, Rust {}", rust.size));
            }
            compare_members(&rust, &spirv, *block, &mut problems);
        }
        (rust, glsl) => problems.push(format!("push constants: Rust {rust:?}, the GLSL {} blocks", glsl.len())),
    }

    // The buffers' structs.
    for rust in interface.structs {
        let found = spirv.laid_out_structs(rust.name);
        if found.is_empty() {
            problems.push(format!("no laid-out struct {} in the module", rust.name));
        }
        for struct_id in found {
            compare_members(rust, &spirv, struct_id, &mut problems);
        }
    }

    // A vertex stage's inputs, location by location.
    let mut inputs: HashMap<u32, u32> = HashMap::new();
    for (variable, pointee) in spirv.variables(StorageClass::Input) {
        if let Some(&location) = spirv.decorations.get(&(variable, Decoration::Location)) {
            inputs.insert(location, spirv.components(pointee));
        }
    }
    if interface.file.ends_with(".vert") {
        for attribute in interface.vertex_inputs {
            let rust = format_components(attribute.format);
            match inputs.remove(&attribute.location) {
                Some(glsl) if glsl == rust => {}
                Some(glsl) => problems.push(format!(
                    "vertex input {}: the GLSL reads {glsl} components, Rust supplies {rust}",
                    attribute.location
                )),
                None => problems.push(format!("vertex input {} is supplied but not read", attribute.location)),
            }
        }
        for location in inputs.keys() {
            problems.push(format!("vertex input {location} is read but not supplied"));
        }
    }
    problems
}

#[test]
fn every_module_has_one_interface() {
    let files: Vec<&str> = interfaces().iter().map(|i| i.file).collect();
    let modules = shaders::ALL.iter().map(|k| k.file).chain(shaders::STAGES.iter().map(|s| s.file));
    for module in modules {
        let count = files.iter().filter(|&&f| f == module).count();
        assert_eq!(count, 1, "{module} has {count} interfaces");
    }
    assert_eq!(files.len(), shaders::ALL.len() + shaders::STAGES.len());
}

#[test]
fn every_module_matches_its_interface() {
    let mut failures = Vec::new();
    for interface in interfaces() {
        for problem in check(&interface) {
            failures.push(format!("glsl/{}: {problem}", interface.file));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The check catches each kind of drift it exists for.
#[test]
fn a_mismatched_interface_is_reported() {
    use lookdev::render::passes::{finalize, relight, resolve};
    let with = |interface: Interface, change: fn(&mut Interface)| {
        let mut changed = interface;
        change(&mut changed);
        check(&changed)
    };
    // The push block of another kernel: wrong name, size and members.
    let problems = with(relight::INTERFACE, |i| i.push = finalize::INTERFACE.push);
    assert!(problems.iter().any(|p| p.contains("push constants")), "{problems:?}");
    // A member moved.
    let problems = with(relight::INTERFACE, |i| {
        let push = i.push.unwrap();
        let mut members = push.members.to_vec();
        members.swap(0, 1);
        let members: Vec<(&'static str, usize)> =
            members.iter().zip(push.members).map(|(&(name, _), &(_, offset))| (name, offset)).collect();
        i.push = Some(GlslStruct { members: Box::leak(members.into_boxed_slice()), ..push });
    });
    assert!(problems.iter().any(|p| p.contains("first_sample")), "{problems:?}");
    // A binding of the wrong kind, and one too many.
    let problems = with(resolve::INTERFACE, |i| i.sets = &[&[BindingKind::StorageBuffer; 8]]);
    assert!(problems.iter().any(|p| p.contains("binding 0")), "{problems:?}");
    assert!(problems.iter().any(|p| p.contains("binding 7 is bound by Rust")), "{problems:?}");
    // A buffer struct with a different stride.
    let problems = with(common::probes::BRDF_PROBE, |i| {
        const SHORT_RECORD: GlslStruct = GlslStruct { size: 80, ..common::probes::BRDF_PROBE.structs[0] };
        i.structs = &[SHORT_RECORD];
    });
    assert!(problems.iter().any(|p| p.contains("step 96 bytes")), "{problems:?}");
    // A vertex attribute of the wrong width.
    let bake_vertex = lookdev::asset::bake::INTERFACES[0];
    let mut attributes = bake_vertex.vertex_inputs.to_vec();
    attributes[1].format = vk::Format::R32G32B32A32_SFLOAT;
    let problems = check(&Interface { vertex_inputs: Box::leak(attributes.into_boxed_slice()), ..bake_vertex });
    assert!(problems.iter().any(|p| p.contains("vertex input 1")), "{problems:?}");
}

/// `Params::to_gpu` against `unpack_material` (material.glsl), read from its source: each
/// `m.<member> = p<k>.<components>;` puts the member at byte 16·k + 4·(first component).
/// Emission, the fifth vec4, is `relight.comp`'s own read of layer 4.
#[test]
fn params_layout_is_unpack_materials() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(root.join("glsl/include/material.glsl")).unwrap();
    let layout = lookdev::material::params::GPU_LAYOUT;
    let mut unpacked = 0;
    for line in source.lines().map(str::trim) {
        let Some(assignment) = line.strip_prefix("m.").and_then(|l| l.strip_suffix(';')) else { continue };
        let (member, value) = assignment.split_once(" = ").expect("m.<member> = p<k>.<components>;");
        let (vector, components) = value.split_once('.').unwrap();
        let k: usize = vector.strip_prefix('p').unwrap().parse().unwrap();
        let first =
            "xyzw".find(components.chars().next().unwrap()).or_else(|| "rgba".find(components.chars().next().unwrap()));
        let offset = 16 * k + 4 * first.unwrap();
        let rust = layout.members.iter().find(|(n, _)| *n == member).map(|&(_, o)| o);
        assert_eq!(rust, Some(offset), "{member}: unpack_material reads byte {offset}");
        unpacked += 1;
    }
    assert_eq!(unpacked, 12, "unpack_material sets the eleven parameters and ior_edge");
    let relight = std::fs::read_to_string(root.join("glsl/relight.comp")).unwrap();
    assert!(relight.contains("vec3 emission = imageLoad(resolved, ivec3(pixel, 4)).rgb;"));
    assert_eq!(layout.members.iter().find(|(n, _)| *n == "emission"), Some(&("emission", 64)));
}

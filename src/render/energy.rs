//! Building a model's energy-compensation table on the GPU (`glsl/energy_table.comp`), once per
//! renderer that needs one.

use crate::gpu::{shaders, Binding, BindingKind, Buffer, ComputePipeline, Context, Interface};
use crate::shading::brdf::{EnergyTable, ENERGY_TABLE_SIZE as SIZE};
use crate::shading::energy::table_from_albedo;
use crate::shading::model::Model;
use crate::Result;

/// What `energy_table.comp` and the host agree on: the table, as one storage buffer.
pub const INTERFACE: Interface = Interface::compute(&shaders::ENERGY_TABLE, &[&[BindingKind::StorageBuffer]], None);

/// E(μ, roughness) for the model's D and G, computed on the GPU, with its averages.
pub fn build(ctx: &Context, model: &Model) -> Result<EnergyTable> {
    let pipeline = ComputePipeline::specialized(
        ctx,
        &shaders::ENERGY_TABLE,
        INTERFACE.sets,
        INTERFACE.push_size(),
        &model.specialization(),
    )?;
    let _timing = crate::timings::phase("energy table");
    let output = Buffer::storage(ctx, (SIZE * SIZE * 4) as u64)?;
    let set = pipeline.bind(0, &[Binding::Buffer(&output)])?;
    ctx.run(|cmd| {
        pipeline.dispatch(cmd, &[&set], &[], [((SIZE * SIZE) as u32).div_ceil(64), 1, 1]);
        Ok(())
    })?;
    let albedo: Vec<f32> = bytemuck::cast_slice(&output.read(ctx)?[..SIZE * SIZE * 4]).to_vec();
    Ok(table_from_albedo(albedo))
}

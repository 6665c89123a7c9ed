//! `gpu+tetragrid` (Table 4-6): the GPU inclusion test over TetraGrid cells — query
//! points grouped by cell, each group drawn against its cell's tetrahedra only.
//!
//! A job is up to 32 points of one cell. Each point-vertex is one batch of a job's list
//! and carries its job and its texel: a job owns consecutive 4×4 tiles of the target, two
//! 2×2 reduction passes sum every tile to one texel, and the host adds the few tile sums
//! of each job. One draw, two reduction passes and one readback per submission: on a
//! software rasterizer every extra pass costs more than the work it would save.

use std::time::Instant;

use glam::DVec3;

use super::classifier::Class;
use super::error::{InclusionError, Result};
use super::gpu::{GROUP_POINTS, GpuStats, LAYERS, MAX_POINTS, TetraSet, Work, classify_pipeline};
use super::tetragrid::GridClassifier;
use crate::gpu::{Attachment, Buffer, Context, Load, Pipeline, Reducer, TexFormat, Texture};

/// Side of the square tiles a job's point-vertices fill (a power of two).
const TILE: u32 = 4;
/// Target size in tiles.
const TILES_WIDE: u32 = 64;
const TILES_HIGH: u32 = 256;

/// Tetrahedra of a cell's list per point-vertex by default (measured on lavapipe).
pub const DEFAULT_BATCH: u32 = 64;

pub struct GpuGridInclusion {
    ctx: Context,
    grid: GridClassifier,
    set: TetraSet,
    /// The grid's CSR tetrahedron lists, as an R32UI texture `lists_width` wide.
    lists: Texture,
    lists_width: u32,
    pipeline: Pipeline,
    batch: u32,
    target: Texture,
    reducer: Reducer,
    points: Buffer,
    jobs: Buffer,
    /// The point-vertices of a submission, and its tile sums copied to the host; both
    /// sized for a full target.
    items: Buffer,
    readback: Buffer,
    stats: GpuStats,
}

impl GpuGridInclusion {
    /// `grid` gives the cell lists and answers flagged points exactly.
    pub fn new(ctx: &Context, grid: GridClassifier, batch: u32) -> Result<GpuGridInclusion> {
        if batch == 0 {
            return Err(InclusionError::Options("batch must be at least 1".into()));
        }
        let set = TetraSet::new(ctx, grid.base())?;
        let ids = grid.cell_lists().1;
        let max = ctx.info().max_image_2d;
        let lists_width = 4096u32.min(max);
        let rows = (ids.len().max(1) as u32).div_ceil(lists_width);
        if rows > max {
            return Err(InclusionError::TooLarge(format!(
                "{} grid entries do not fit one texture",
                ids.len()
            )));
        }
        let lists = Texture::new(ctx, TexFormat::R32Ui, lists_width, rows, "tetragrid lists")?;
        let mut padded = ids.to_vec();
        padded.resize((lists_width * rows) as usize, 0);
        ctx.submit(|rec| rec.upload(&lists, 0, &padded))?;
        let size = [TILE * TILES_WIDE, TILE * TILES_HIGH];
        let target =
            Texture::new_layered(ctx, TexFormat::Rgba32F, size[0], size[1], LAYERS, "phase 1 (grid)")?;
        Ok(GpuGridInclusion {
            ctx: ctx.clone(),
            reducer: Reducer::for_tiles(ctx, size, [TILE, TILE], LAYERS)?,
            points: Buffer::host(ctx, (MAX_POINTS * 16) as u64, "query points")?,
            jobs: Buffer::host(ctx, (MAX_POINTS * 16) as u64, "grid jobs")?,
            items: Buffer::host(
                ctx,
                u64::from(TILES_WIDE * TILES_HIGH * TILE * TILE) * 16,
                "grid point-vertices",
            )?,
            readback: Buffer::readback_for(ctx, u64::from(LAYERS * TILES_WIDE * TILES_HIGH) * 16)?,
            grid,
            set,
            lists,
            lists_width,
            pipeline: classify_pipeline(ctx, true)?,
            batch,
            target,
            stats: GpuStats::default(),
        })
    }

    pub fn stats(&self) -> &GpuStats {
        &self.stats
    }

    pub fn grid(&self) -> &GridClassifier {
        &self.grid
    }

    /// Classifies every point; where the time went lands in [`Self::stats`].
    pub fn classify_all(&mut self, points: &[DVec3]) -> Result<Vec<Class>> {
        let (mut work, todo) = Work::triage(self.grid.base(), &self.set, points);
        // Points by cell; points outside the grid's cube, or in cells no tetrahedron
        // reaches, are Outside (their inclusion sum is 0).
        let mut by_cell: Vec<(u32, usize)> = todo
            .into_iter()
            .filter_map(|i| {
                let c = self.grid.cell_of(points[i])?;
                (!self.grid.cell_tetras(c).is_empty()).then_some((c as u32, i))
            })
            .collect();
        by_cell.sort_unstable();
        work.stats.gpu_points = by_cell.len();
        let tile_capacity = TILES_WIDE * TILES_HIGH;
        let per_tile = TILE * TILE * self.batch;
        let mut k = 0;
        while k < by_cell.len() {
            // Jobs of up to 32 points of one cell, while the points fit the uniform block
            // (each job reads a 32-point window) and their tiles fit the target.
            let mut jobs: Vec<[u32; 4]> = Vec::new();
            let mut order = Vec::new();
            let mut tiles = 0;
            while k < by_cell.len() && order.len() + GROUP_POINTS <= MAX_POINTS {
                let cell = by_cell[k].0 as usize;
                let list = self.grid.cell_tetras(cell).len() as u32;
                let need = list.div_ceil(per_tile);
                if tiles + need > tile_capacity {
                    if jobs.is_empty() {
                        return Err(InclusionError::TooLarge(format!(
                            "a grid cell lists {list} tetrahedra, more than one draw holds; raise the batch size"
                        )));
                    }
                    break;
                }
                let first = order.len();
                while k < by_cell.len() && by_cell[k].0 as usize == cell && order.len() - first < GROUP_POINTS
                {
                    order.push(by_cell[k].1);
                    k += 1;
                }
                let start = self.grid.cell_lists().0[cell];
                jobs.push([start, list, first as u32, (order.len() - first) as u32]);
                tiles += need;
            }
            let sums = self.run_jobs(points, &order, &jobs, &mut work.stats)?;
            work.take(&order, &sums);
        }
        let (out, stats) = work.finish(&self.grid, points);
        self.stats = stats;
        Ok(out)
    }

    /// One submission: one draw of every (job, batch) point-vertex, tiles reduced to one
    /// texel each, read back, and each job's tile sums added. Returns a sum per point of
    /// `order`.
    fn run_jobs(
        &mut self,
        points: &[DVec3],
        order: &[usize],
        jobs: &[[u32; 4]],
        stats: &mut GpuStats,
    ) -> Result<Vec<f32>> {
        let chunk: Vec<DVec3> = order.iter().map(|&i| points[i]).collect();
        self.points.write_slice(0, &self.set.point_block(&chunk))?;
        self.jobs.write_slice(0, jobs)?;
        // Point-vertices (job, batch, texel); tile t sits at (t % TILES_WIDE, t / TILES_WIDE).
        let per_tile = TILE * TILE;
        let mut items: Vec<[u32; 4]> = Vec::new();
        let mut job_tiles = Vec::with_capacity(jobs.len());
        let mut tile = 0u32;
        for (j, job) in jobs.iter().enumerate() {
            let batches = job[1].div_ceil(self.batch);
            for b in 0..batches {
                let t = tile + b / per_tile;
                let within = b % per_tile;
                let x = (t % TILES_WIDE) * TILE + within % TILE;
                let y = (t / TILES_WIDE) * TILE + within / TILE;
                items.push([j as u32, b, x, y]);
            }
            job_tiles.push(tile..tile + batches.div_ceil(per_tile));
            tile += batches.div_ceil(per_tile);
        }
        self.items.write_slice(0, &items)?;
        let tiles = tile.max(1);
        let (tx, ty) = (TILES_WIDE.min(tiles), tiles.div_ceil(TILES_WIDE));
        let size = [tx * TILE, ty * TILE];
        let push = self.set.params(size, 0, self.batch, self.lists_width);
        let count = items.len() as u32;
        let t = Instant::now();
        let attachments = Attachment::each_layer(&self.target, Load::Zero);
        let reads = [&self.set.texture, &self.lists];
        let (pipeline, target, tetras, lists, ubo, job_ubo, vertices, readback, reducer) = (
            &self.pipeline,
            &self.target,
            &self.set.texture,
            &self.lists,
            &self.points,
            &self.jobs,
            &self.items,
            &self.readback,
            &mut self.reducer,
        );
        self.ctx.submit(|rec| {
            rec.render(&attachments, Some([0, 0, size[0], size[1]]), &reads, |pass| {
                pass.bind(pipeline)?;
                pass.textures(&[(0, tetras), (2, lists)])?;
                pass.uniform(1, ubo)?;
                pass.uniform(3, job_ubo)?;
                pass.push(&push)?;
                pass.vertex_buffers(vertices, None)?;
                pass.draw(0..count, 0..1)
            })?;
            let sums = reducer.record_tiles(rec, target, size, [TILE, TILE])?;
            rec.readback_into(sums, 0..LAYERS, [0, 0, tx, ty], readback, 0)
        })?;
        stats.gpu += t.elapsed();
        stats.draws += 1;
        let t = Instant::now();
        let texels = self.readback.view::<[f32; 4]>()?;
        let per_layer = (tx * ty) as usize;
        let mut sums = vec![0.0f32; order.len()];
        for (job, tiles) in jobs.iter().zip(&job_tiles) {
            for slot in 0..job[3] as usize {
                let base = (slot / 4) * per_layer;
                // The host adds this job's tile sums (a handful): exact integers.
                sums[job[2] as usize + slot] =
                    tiles.clone().map(|t| texels[base + t as usize][slot % 4]).sum();
            }
        }
        stats.host += t.elapsed();
        Ok(sums)
    }
}

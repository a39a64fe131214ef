//! GPU milliseconds of Bevy's whole frame: a timestamp before the cameras' render schedules and one after,
//! in the command buffers Bevy submits together, every frame.

use bevy::core_pipeline::schedule::camera_driver;
use bevy::prelude::*;
use bevy::render::renderer::{
    PendingCommandBuffers, RenderDevice, RenderGraph, RenderGraphSystems, RenderQueue,
};
use bevy::render::RenderApp;
use hrts_wgpu::SpanTimer;
use std::sync::{Arc, Mutex};

/// The frames' GPU milliseconds, in the order the GPU completed them: readable in the main world.
#[derive(Resource, Clone, Default)]
pub struct FrameTimes(pub Arc<Mutex<Vec<f64>>>);

/// Times every frame into its [`FrameTimes`] if Bevy's device writes timestamps inside command encoders
/// (add it after `DefaultPlugins`: it needs Bevy's device).
pub struct FrameTimerPlugin(pub FrameTimes);

#[derive(Resource)]
struct FrameTimer(SpanTimer, FrameTimes);

impl Plugin for FrameTimerPlugin {
    fn build(&self, _app: &mut App) {}

    fn finish(&self, app: &mut App) {
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
            return;
        };
        let world = render_app.world();
        let device = world.resource::<RenderDevice>().wgpu_device();
        let Some(timer) = SpanTimer::new(device, world.resource::<RenderQueue>()) else {
            eprintln!(
                "no GPU frame times: the device writes no timestamps inside command encoders"
            );
            return;
        };
        render_app
            .insert_resource(FrameTimer(timer, self.0.clone()))
            .add_systems(
                RenderGraph,
                (
                    begin
                        .in_set(RenderGraphSystems::Render)
                        .before(camera_driver),
                    end.in_set(RenderGraphSystems::Render).after(camera_driver),
                    submitted.in_set(RenderGraphSystems::Finish),
                ),
            );
    }
}

/// The frame's first timestamp, in a command buffer of its own submitted before the cameras' ones.
fn begin(
    mut timer: ResMut<FrameTimer>,
    device: Res<RenderDevice>,
    mut pending: ResMut<PendingCommandBuffers>,
) {
    let FrameTimer(timer, times) = &mut *timer;
    // Every frame timed: Bevy runs at most the timer's 8 frames ahead of the GPU.
    timer.wait_for_slot(device.wgpu_device());
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    timer.begin(device.wgpu_device(), &mut encoder);
    times
        .0
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .extend(timer.take());
    pending.push([encoder.finish()]);
}

/// The frame's last timestamp, submitted after the cameras' command buffers.
fn end(
    mut timer: ResMut<FrameTimer>,
    device: Res<RenderDevice>,
    mut pending: ResMut<PendingCommandBuffers>,
) {
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    timer.0.end(&mut encoder);
    pending.push([encoder.finish()]);
}

fn submitted(mut timer: ResMut<FrameTimer>) {
    timer.0.submitted();
}

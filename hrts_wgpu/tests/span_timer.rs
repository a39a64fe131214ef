//! `SpanTimer` on the Vulkan device the tests run on (lavapipe in CI): each submitted span comes back once,
//! as a positive duration; a span never ended, or begun while its slot was still being read back, adds
//! none; waiting for the slot times every span.

use hrts_wgpu::SpanTimer;

fn device() -> (wgpu::Device, wgpu::Queue) {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: wgpu::Backends::VULKAN,
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    let adapter = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN))
        .into_iter()
        .next()
        .expect("a Vulkan adapter (lavapipe in CI)");
    let features =
        wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
    assert!(
        adapter.features().contains(features),
        "{} writes no timestamps inside encoders",
        adapter.get_info().name
    );
    pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: features,
        ..Default::default()
    }))
    .expect("a device")
}

#[test]
fn each_submitted_span_is_read_back_once() {
    let (device, queue) = device();
    let mut timer = SpanTimer::new(&device, &queue).expect("timestamps inside encoders");
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 64 << 20,
        usage: wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut times = Vec::new();
    for frame in 0..6 {
        let mut encoder = device.create_command_encoder(&Default::default());
        timer.begin(&device, &mut encoder);
        times.extend(timer.take());
        encoder.clear_buffer(&buffer, 0, None);
        // Frame 3's span is never ended: it is dropped, not read back.
        if frame != 3 {
            timer.end(&mut encoder);
        }
        queue.submit([encoder.finish()]);
        timer.submitted();
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("the frame completes");
    }
    let mut encoder = device.create_command_encoder(&Default::default());
    timer.begin(&device, &mut encoder);
    times.extend(timer.take());
    assert_eq!(times.len(), 5, "{times:?}");
    assert!(
        times.iter().all(|&ms| ms > 0.0 && ms < 60_000.0),
        "{times:?}"
    );
    // 12 spans in a row without waiting for the GPU: the 8 slots time at least 8 of them; waiting for the
    // slot times all 12.
    for wait in [false, true] {
        let mut timed = 0;
        for _ in 0..12 {
            if wait {
                timer.wait_for_slot(&device);
            }
            let mut encoder = device.create_command_encoder(&Default::default());
            timer.begin(&device, &mut encoder);
            timed += timer.take().len();
            encoder.clear_buffer(&buffer, 0, None);
            timer.end(&mut encoder);
            queue.submit([encoder.finish()]);
            timer.submitted();
        }
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("the frames complete");
        let mut encoder = device.create_command_encoder(&Default::default());
        timer.begin(&device, &mut encoder);
        timed += timer.take().len();
        if wait {
            assert_eq!(timed, 12);
        } else {
            assert!((8..=12).contains(&timed), "{timed} spans timed");
        }
    }
}

//! The coordinator's IPC: the iceoryx2 node of a run, the single server of
//! `<run>/work` and the two event ports; waiting (a WaitSet on the to-coord
//! event plus a tick, never busy-polling), receiving, decoding, responding.
//! Must not touch the plan, the journal or worker processes.

use std::time::{Duration, SystemTime, UNIX_EPOCH};

use anyhow::{anyhow, bail};
use iceoryx2::active_request::ActiveRequest;
use iceoryx2::config::Config;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use iceoryx2::waitset::WaitSetRunResult;
use protocol::{Decoded, Envelope, ProtocolError, ToCoord, ToWorker};
use worker::{WireScalars, WireSpec};

use crate::case::CaseKey;

/// Worker → coordinator message of this build.
pub type WorkerMessage = ToCoord<CaseKey, WireScalars>;
/// Coordinator → worker message of this build.
pub type CoordMessage = ToWorker<CaseKey, WireSpec>;

type Active = ActiveRequest<ipc::Service, [u8], (), [u8], ()>;

/// One request of a worker, not yet answered. Dropping it unanswered
/// releases it; holding it keeps the worker waiting.
pub struct Request {
    active: Active,
    received_ns: u64,
}

impl Request {
    /// When it was taken from the queue, ns since the Unix epoch.
    pub fn received_ns(&self) -> u64 {
        self.received_ns
    }

    /// Bytes of its payload.
    pub fn payload_len(&self) -> usize {
        self.active.payload().len()
    }
}

/// Nanoseconds since the Unix epoch (clocks of one machine; 0 if unknown).
pub fn unix_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos() as u64)
        .unwrap_or(0)
}

/// A run stopped by Ctrl-C or SIGTERM (typed, so that the Python module can
/// raise `KeyboardInterrupt` for it), naming the caller's way to resume.
#[derive(Debug, thiserror::Error)]
#[error("interrupted; the journal keeps what was recorded (continue with {resume})")]
pub struct Interrupted {
    /// The option that continues the run (`--resume`, `resume=True`).
    pub resume: &'static str,
}

/// What a step of [`Exchange::wait_loop`] asks for next.
pub enum Next {
    /// End the loop.
    Done,
    /// Wait again, for a notification or the tick, but at most this long
    /// (`Duration::MAX`: the tick alone bounds it).
    Within(Duration),
}

/// The IPC endpoints of one run.
pub struct Exchange<'a> {
    run_id: &'a str,
    cfg: Config,
    node: Node<ipc::Service>,
    server: Server<ipc::Service, [u8], (), [u8], ()>,
    listener: Listener<ipc::Service>,
    notifier: Notifier<ipc::Service>,
    names: super::OptionNames,
}

impl<'a> Exchange<'a> {
    /// Create the node and services of run `run_id`, sized for `workers`;
    /// an interruption names the caller's options (`names`).
    pub fn open(
        run_id: &'a str,
        workers: usize,
        names: super::OptionNames,
    ) -> anyhow::Result<Self> {
        let cfg = protocol::ipc_config()?;
        let node = protocol::create_node(
            &cfg,
            &protocol::coord_node_name(run_id),
            SignalHandlingMode::HandleTerminationRequests,
        )?;
        node.try_cleanup_dead_nodes();
        let work = protocol::work_service_port(&node, run_id, workers, true)?;
        let server = work
            .server_builder()
            .initial_max_slice_len(4096)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(|e| anyhow!("cannot create the work server: {e:?}"))?;
        let listener =
            protocol::event_service_port(&node, &protocol::to_coord_event(run_id), workers, true)?
                .listener_builder()
                .create()
                .map_err(|e| anyhow!("cannot create listener: {e:?}"))?;
        let notifier = protocol::event_service_port(
            &node,
            &protocol::to_workers_event(run_id),
            workers,
            true,
        )?
        .notifier_builder()
        .create()
        .map_err(|e| anyhow!("cannot create notifier: {e:?}"))?;
        Ok(Exchange {
            run_id,
            cfg,
            node,
            server,
            listener,
            notifier,
            names,
        })
    }

    /// The iceoryx2 config of the run (for listing nodes).
    pub fn config(&self) -> &Config {
        &self.cfg
    }

    /// Remove what dead nodes left behind.
    pub fn cleanup_dead_nodes(&self) {
        self.node.try_cleanup_dead_nodes();
    }

    /// Wake on every worker notification and at least every `tick`, calling
    /// `step` each time until it returns [`Next::Done`]; [`Next::Within`]
    /// bounds the next wait further. A termination request (Ctrl-C,
    /// SIGTERM) ends the loop with an error; other signals (a pause and
    /// resume) do not.
    pub fn wait_loop(
        &self,
        tick: Duration,
        mut step: impl FnMut() -> anyhow::Result<Next>,
    ) -> anyhow::Result<()> {
        let waitset = WaitSetBuilder::new()
            .create::<ipc::Service>()
            .map_err(|e| anyhow!("cannot create waitset: {e:?}"))?;
        let _event = waitset
            .attach_notification(&self.listener)
            .map_err(|e| anyhow!("cannot attach listener: {e:?}"))?;
        let _tick = waitset
            .attach_interval(tick)
            .map_err(|e| anyhow!("cannot attach interval: {e:?}"))?;
        let mut within = Duration::MAX;
        loop {
            match waitset
                .wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, within)
            {
                Ok(WaitSetRunResult::TerminationRequest) => {
                    return Err(Interrupted {
                        resume: self.names.resume,
                    }
                    .into())
                }
                // Any other signal cut the wait short: SIGCONT after a pause
                // (Ctrl-Z and `fg`, a debugger, `scontrol suspend`/`resume`)
                // ended a sweep here (#33 item 4). Not a request to stop: go
                // on. A SIGINT or SIGTERM that cut it short is seen as a
                // termination request by the next wait, which checks first.
                Ok(_) => {}
                Err(e) => bail!("waiting failed: {e:?}"),
            }
            let _ = self.listener.try_wait(|_| {});
            match step()? {
                Next::Done => return Ok(()),
                Next::Within(d) => within = d,
            }
        }
    }

    /// The next waiting request, if any.
    pub fn receive(&self) -> anyhow::Result<Option<Request>> {
        let active = self
            .server
            .receive()
            .map_err(|e| anyhow!("receive failed: {e:?}"))?;
        Ok(active.map(|active| Request {
            active,
            received_ns: unix_ns(),
        }))
    }

    /// Decode a request (version, run id and header checked; the field
    /// arrays stay borrowed from the payload).
    pub fn decode<'r>(
        &self,
        request: &'r Request,
    ) -> Result<Decoded<'r, WorkerMessage>, ProtocolError> {
        protocol::decode_to_coord(request.active.payload(), self.run_id)
    }

    /// Answer a request (call [`Exchange::notify`] after a batch of answers).
    pub fn respond(&self, request: &Request, msg: &CoordMessage) -> anyhow::Result<()> {
        let header = protocol::encode_header(&Envelope::new(self.run_id, msg))?;
        let len = protocol::frame_len(header.len(), 0);
        let mut response = request
            .active
            .loan_slice(len)
            .map_err(|e| anyhow!("cannot loan a response: {e:?}"))?;
        protocol::encode_into(response.payload_mut(), &header, &[])?;
        response
            .send()
            .map_err(|e| anyhow!("cannot send a response: {e:?}"))?;
        Ok(())
    }

    /// Wake the workers waiting for answers.
    pub fn notify(&self) {
        let _ = self.notifier.notify();
    }
}

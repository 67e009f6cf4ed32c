# Copyright 2026 The hyst_id authors
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""Live identification without ROS: samples, pairing, background jobs, the result.

What the identifier node (:mod:`hyst_id.nodes.identifier`) does that does
not need ``rclpy`` lives here, so it is tested and reused without a ROS
installation:

* :class:`SampleBuffer` collects the command and measurement streams of a
  run (stamps in ns) and turns them into a :class:`~hyst_id.io.recording.Recording`
  with :func:`hyst_id.io.streams.pair_streams`, which pairs each measurement with the last
  command at or before it exactly as the bag reader
  (:func:`hyst_id.io.mcap_reader.read_mcap`) does, with the same sorting and
  de-duplication of each stream (:func:`hyst_id.io.streams.tidy_stream`, one
  implementation for both) and the same notes; it also notes gaps in the
  measurement stream (samples lost in transit);
* :class:`IdentificationJob` and :class:`DiagnosisJob` run
  :func:`hyst_id.identification.identify` / :func:`hyst_id.diagnosis.diagnose` in a
  worker thread, can be cancelled (:meth:`BackgroundJob.cancel`: between two
  seeds, or two diagnosis steps) and never raise into the caller;
* :func:`compensator_set`, :func:`result_document` and
  :func:`diagnosis_statuses` build what the node publishes.

Modules: :mod:`.buffer` (samples), :mod:`.jobs` (worker threads),
:mod:`.documents` (what the node publishes), :mod:`.gate` (when a set is
held back from the compensator), :mod:`.sliding` (re-identification on a
sliding window of live data and the rule for swapping its set in).

May import: :mod:`hyst_id.io`, :mod:`hyst_id.identification`, :mod:`hyst_id.compensation`,
:mod:`hyst_id.diagnosis`; never rclpy.
"""

from hyst_id.io.streams import pair_streams
from hyst_id.live.buffer import SampleBuffer
from hyst_id.live.documents import (
                                    compensator_set,
                                    diagnosis_statuses,
                                    recovered_document,
                                    result_document,
                                    warm_up_kernels,
)
from hyst_id.live.gate import QualityGate
from hyst_id.live.jobs import BackgroundJob, DiagnosisJob, IdentificationJob, JobCancelled

__all__ = ['BackgroundJob', 'DiagnosisJob', 'IdentificationJob', 'JobCancelled',
           'QualityGate', 'SampleBuffer', 'compensator_set', 'diagnosis_statuses', 'pair_streams',
           'recovered_document', 'result_document', 'warm_up_kernels']

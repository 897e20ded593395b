;;> The live view: a page on localhost that draws the lab as it runs and
;;> replays a finished run from its trace (\scheme{murdoch view}, \scheme{murdoch replay}).
(define-library (murdoch view)
  (export run-view run-replay
          ;; the parts, for tests
          lab-header default-trace view-snapshot new-view-state make-task-table
          task-table-update! task-table-note-line!
          task-table->json reservation-task json-text box-seen)
  (import (only (murdoch code) make-logged-thread) (only (murdoch wire) error-message)
          (only (murdoch task) task-key-parts listed-posed? listed-id listed-state
                listed-place listed-why listed-index ended-id ended-index ended-started
                ended-ended ended-end)
          (only (murdoch robot) fiducial-id fiducial-range fiducial-bearing
                fiducial-orientation)
          (only (murdoch task) report-since report-pose report-battery report-held
                report-tasks report-goal report-ended held-subject held-holder
                report-handed lab-task-id lab-task-role lab-task-state
                lab-task-coordinator lab-task-standby lab-line waiting-text)
          (scheme base) (scheme write)
          (scheme file) (scheme eval) (scheme inexact) (scheme char) (srfi 1) (srfi 18)
          (chibi net) (chibi net http-server) (chibi net servlet)
          (only (chibi config) make-conf) (only (chibi process) current-process-id)
          (only (chibi io) file->string)
          (only (chibi filesystem) create-directory* open open/write open/append
                open/create open/exclusive open-output-file-descriptor)
          (only (srfi 151) bitwise-ior) (only (srfi 132) list-stable-sort) (chibi json)
          (murdoch sys) (murdoch lab) (murdoch cli) (murdoch remote))
  (include "view/snapshot.scm" "view/tasks.scm" "view/serve.scm"))

;;> The lab file (docs/lab-file.md): who is in the lab and where, and every
;;> setting in one table.

(define-library (murdoch lab)
  (export read-lab lab? lab-name lab-aspaces lab-setting lab-default
          lab-port-base planned-port lab-planned-port lab-guest-port
          lab-trip-port lab-trip-host lab-path lab-aspace-by-uid lab-robots
          lab-key lab-clause lab-robot-radius read-source unread-lab-port-base
          lab-aspace-uid lab-aspace-index lab-aspace-host lab-aspace-port
          lab-aspace-clause random-hex lab-walls lab-boxes wall-from wall-to wall-thickness
          box-centre box-width box-depth box-heading
          *node* open-node! this-node current-lab setting call-timeout
          node-wire node-wire-set! node-limits node-limits-set!
          node-sandbox node-sandbox-set! node-membership node-membership-set!
          node-connections node-connections-set!
          node-server node-server-set! node-group node-group-set!
          node-subscriber node-subscriber-set! node-monitors node-monitors-set!
          node-teams node-teams-set! node-poses node-poses-set! node-runs node-runs-set!
          node-posed node-posed-set! node-line node-line-set! node-looking
          node-looking-set! node-offering node-offering-set! node-handing
          node-handing-set!)
  (import (scheme base) (scheme char) (scheme read) (scheme write) (scheme file)
          (scheme process-context)
          (scheme inexact)
          (srfi 1) (srfi 151)
          (only (chibi filesystem) open open/write open/create open/exclusive
                open-output-file-descriptor link-file)
          (only (chibi process) current-process-id)
          (only (chibi ast) port-line)
          (chibi io) (chibi edit-distance)
          (only (murdoch sys) condition-message))
  (include "lab/file.scm" "lab/settings.scm" "lab/clauses.scm" "lab/source.scm"
           "lab/room.scm" "lab/key.scm"
           "lab/node.scm"))

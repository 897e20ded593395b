;;> For tests alone: labs in temporary folders on free ports, and child
;;> processes that are always stopped.

(define-library (murdoch testing harness)
  (export make-test-lab test-lab-file test-lab-directory test-lab-port-base
          start-process! stop-process! kill-process! reap! reaped-if-ended!
          stop-all-processes!
          start-lab-aspace! start-murdoch-lab! median-seconds
          wait-for-port wait-until remove-test-lab!
          tool-path temporary-directory free-port-base file-text
          text-contains? files-under listen-on-free-port read-lines text-lines error-text
          command-output)
  (import (scheme base) (scheme time) (scheme write) (scheme file)
          (scheme read) (scheme process-context)
          (only (srfi 1) append-map) (srfi 18) (srfi 132)
          (chibi net) (chibi process) (chibi io)
          (only (chibi string) string-suffix?)
          (only (chibi ast) unsetenv errno integer->error-string)
          (murdoch lab) (only (murdoch wire) open-connection)
          (only (murdoch remote) remote-error? remote-error-message)
          (only (murdoch sys) die-with-parent!)
          (only (chibi test) test-failure-count)
          (only (chibi filesystem) delete-file-hierarchy current-directory directory-files
                file-directory?
                create-directory
                open-input-file-descriptor open-output-file-descriptor
                open-pipe duplicate-file-descriptor-to))
  (include "harness.scm"))

;;> Address spaces: the local one, the peers it knows, which of them
;;> answer, and the settings every call reads.

(define-library (murdoch remote aspace)
  (export aspace? aspace-uid aspace-host aspace-port make-aspace
          local-aspace local-aspace-uid local-aspace-port-set!
          aspace-started-at uid->aspace known-uids
          learn-aspace! note-unreachable! note-reachable! unreachable-uids
          live-uids live-aspaces live-aspace join-lab!
          remote-timeout current-timeout
          lab-environment decode-value describe-procedure)
  (import (scheme base) (srfi 1) (srfi 18) (srfi 69) (murdoch sys) (murdoch lab)
          (murdoch code))
  (include "aspace.scm"))

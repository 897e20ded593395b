;;; Publish/subscribe between real address spaces, with the thesis's
;;; simulated broadcast: each message is sent to each address space.
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (srfi 1) (srfi 18) (srfi 132) (chibi test)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (only (murdoch pubsub) request-components)
        (murdoch cli command) (murdoch testing harness))

(define delivery '())
(include "tests/pubsub-cases.scm")     ; run from the top, as tests/run does

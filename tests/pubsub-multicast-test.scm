;;; Publish/subscribe between real address spaces, delivered by IP
;;; multicast on loopback: one datagram reaches every address space.
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (srfi 1) (srfi 18) (srfi 132) (chibi test)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (only (murdoch pubsub) request-components)
        (murdoch cli command) (murdoch testing harness))

(define delivery '((delivery multicast "239.255.77.7")))
(include "tests/pubsub-cases.scm")     ; run from the top, as tests/run does

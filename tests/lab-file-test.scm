;;; The lab file's settings: one table of names, defaults and checks
;;; (lib/murdoch/lab.scm), read once, every mistake named with its clause.
(import (scheme base) (scheme write) (scheme file) (chibi test)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch lab) (murdoch testing))

(define dir (temporary-directory))
(define file (string-append dir "/lab.scm"))

;; The lab whose clauses are text, read; or the message of its error.
(define (read-text text)
  (call-with-output-file file (lambda (out) (write-string text out)))
  (guard (e ((error-object? e) (error-object-message e)))
    (read-lab file)))

(define (setting text key)
  (let ((lab (read-text text)))
    (if (lab? lab) (lab-setting lab key) lab)))

(define (says? text what)
  (let ((message (read-text text)))
    (and (string? message) (text-contains? message what))))

(test-begin "lab-file")

(test-group "defaults come from the table"
  (test 5 (setting "(lab x)" 'timeout))
  (test 4000 (setting "(lab x)" 'max-depth))
  (test '(broadcast) (setting "(lab x)" 'delivery))
  (test '() (setting "(lab x)" 'code))
  (test (* 512 1024 1024) (setting "(lab x)" 'heap-max)))

(for-each (lambda (name)
            (call-with-output-file (string-append dir "/" name)
              (lambda (out) (write-string "(define x 1)\n" out))))
          '("a.scm" "b.scm"))

(test-group "what the file says is read"
  (test 2.5 (setting "(lab x (timeout 2.5))" 'timeout))
  (test (* 160 1024 1024) (setting "(lab x (heap-max \"160M\"))" 'heap-max))
  (test '(multicast "239.1.1.1" 5000)
    (setting "(lab x (delivery multicast \"239.1.1.1\" 5000))" 'delivery))
  (test '("a.scm" "b.scm") (setting "(lab x (code \"a.scm\" \"b.scm\"))" 'code)))

(test-group "mistakes are named, with their clause"
  (test "an unknown setting, with the nearest" #t
    (says? "(lab x (timout 3))" "(timout 3): no such setting; did you mean timeout?"))
  (test "one far from any" #t
    (says? "(lab x (colour blue))" "(colour blue): no such setting"))
  (test "a wrong value" #t
    (says? "(lab x (timeout -1))" "(timeout -1): timeout takes a positive number of seconds"))
  (test "too many values" #t
    (says? "(lab x (lease 1 2))" "(lease 1 2): lease takes a positive number of seconds"))
  (test "a max-depth past what Chibi's writer keeps" #t
    (says? "(lab x (max-depth 20000))" "max-depth takes a whole number from 1 to 9000"))
  (test "a size that is none" #t
    (says? "(lab x (heap-max \"12Q\"))" "heap-max takes bytes"))
  (test "a delivery that is neither" #t
    (says? "(lab x (delivery carrier-pigeon))" "delivery takes broadcast, or multicast"))
  (test "the file is named" #t (says? "(lab x (timout 3))" file))
  (test "two address spaces of one name" #t
    (says? "(lab x (aspace a) (aspace b) (aspace a))" "(aspace a): two address spaces of this name"))
  (test "two things on one port" #t
    (says? "(lab x (port-base 7000) (aspace a) (aspace b (port 7000)))"
           "(port 7000): two things on this port"))
  (test "a robot's trip server on an address space's port" #t
    (says? "(lab x (port-base 7000) (aspace a (robot (trip-port 7001))) (aspace b))"
           "(port 7001): two things on this port"))
  (test "a code file that is not there" #t
    (says? "(lab x (code \"nowhere.scm\"))" "(code \"nowhere.scm\"): no such file")))

(test-group "the line of the clause"
  (test "a mistake on line 4 says :4:" #t
    (says? "; a lab\n(lab x\n  (lease 30)\n  (timout 3))\n" (string-append file ":4: (timout 3)"))))

(define room
  "(lab x (world (wall -3000 -3000 3000 -3000) (box 1500 1500 600 600 30))\n")

(test-group "robots placed where they cannot stand"
  (test "inside a wall" #t
    (says? (string-append room "(aspace a (robot (pose 0 -2990 0))))")
           "the robot a stands inside or against (wall -3000 -3000 3000 -3000)"))
  (test "on a box" #t
    (says? (string-append room "(aspace a (robot (pose 1500 1700 0))))")
           "the robot a stands on (box 1500 1500 600 600 30)"))
  (test "on another robot, on its own line" #t
    (says? (string-append room "(aspace a (robot (pose 0 0 0)))\n(aspace b (robot (pose 200 100 0))))")
           ":2: (aspace a (robot (pose 0 0 0))): the robot a stands on the robot b"))
  (test "apart, they are fine" #t
    (lab? (read-text (string-append room "(aspace a (robot (pose 0 0 0))) (aspace b (robot (pose 1000 0 0))))"))))
  (test "a larger radius from the b14 clause counts" #t
    (says? (string-append room "(b14 (radius 600)) (aspace a (robot (pose 0 0 0))) (aspace b (robot (pose 1000 0 0))))")
           "stands on the robot b")))

(test-end)
(delete-file-hierarchy dir)
(test-exit)

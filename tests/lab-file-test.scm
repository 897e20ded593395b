;;; The lab file's settings: one table of names, defaults and checks
;;; (lib/murdoch/lab/settings.scm), read once, every mistake named with its clause.
(import (scheme base) (scheme write) (scheme file) (chibi test)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch lab) (murdoch testing harness))

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
    (says? "(lab x (timeout -1))"
           "(timeout -1): timeout takes a positive number of seconds"))
  (test "too many values" #t
    (says? "(lab x (lease 1 2))" "(lease 1 2): lease takes a positive number of seconds"))
  (test "a max-depth past what Chibi's writer keeps" #t
    (says? "(lab x (max-depth 20000))" "max-depth takes a whole number from 1 to 9000"))
  (test "a size that is none" #t
    (says? "(lab x (heap-max \"12Q\"))" "heap-max takes bytes"))
  (test "a delivery that is neither" #t
    (says? "(lab x (delivery carrier-pigeon))" "delivery takes broadcast, or multicast"))
  (test "a lost-periods that leaves a stale component no period to stop in" #t
    (says? "(lab x (orphan-periods 3) (lost-periods 4))"
           "(lost-periods 4): lost-periods must be at least orphan-periods + 1.25"))
  (test "an orphan-periods that does, the clause at fault named" #t
    (says? "(lab x (orphan-periods 3))"
           "(orphan-periods 3): lost-periods must be at least orphan-periods + 1.25"))
  (test "periods that leave one are read" '(1 2.25)
    (list (setting "(lab x (orphan-periods 1) (lost-periods 2.25))" 'orphan-periods)
          (setting "(lab x (orphan-periods 1) (lost-periods 2.25))" 'lost-periods)))
  (test "the file is named" #t (says? "(lab x (timout 3))" file))
  (test "a ROS 2 robot's clause, within its robot" #t
    (says? "(lab x (aspace a (robot (ros2 (namespace \"/a\") (arrive-mm 0)))))"
           "(arrive-mm 0): arrive-mm takes a positive number of millimetres"))
  (test "two address spaces of one name: the later, with the other's line" #t
    (says? "(lab x\n (aspace a)\n (aspace b)\n (aspace a))"
           ":4: (aspace a): two address spaces of this name: the other on line 2"))
  (test "two things on one port: both named" #t
    (says? "(lab x (port-base 7000)\n (aspace a)\n (aspace b (port 7000)))"
           (string-append ":3: (aspace b (port 7000)): two things on port 7000:"
                          " the address space a on line 2, and the address space b")))
  (test "a robot's trip server on an address space's port" #t
    (says? "(lab x (port-base 7000)\n (aspace a (robot (trip-port 7001)))\n (aspace b))"
           (string-append ":3: (aspace b): two things on port 7001: the trip server"
                          " of the robot a on line 2, and the address space b")))
  (test "a code file that is not there" #t
    (says? "(lab x (code \"nowhere.scm\"))" "(code \"nowhere.scm\"): no such file")))

(test-group "the line of the clause"
  (test "a mistake on line 4 says :4:" #t
    (says? "; a lab\n(lab x\n  (lease 30)\n  (timout 3))\n"
           (string-append file ":4: (timout 3)"))))

(define room
  "(lab x (world (wall -3000 -3000 3000 -3000) (box 1500 1500 600 600 30))\n")

(test-group "robots placed where they cannot stand"
  (test "inside a wall" #t
    (says? (string-append room "(aspace a (robot (pose 0 -2990 0))))")
           "the robot a stands inside or against (wall -3000 -3000 3000 -3000)"))
  (test "on a box" #t
    (says? (string-append room "(aspace a (robot (pose 1500 1700 0))))")
           "the robot a stands on (box 1500 1500 600 600 30)"))
  (test "on another robot: the later is named, on its line, with the other's" #t
    (says? (string-append room "(aspace a (robot (pose 0 0 0)))\n"
                          "(aspace b (robot (pose 200 100 0))))")
           (string-append ":3: (aspace b (robot (pose 200 100 0))): the robot b stands on"
                          " the robot a on line 2")))
  (test "apart, they are fine" #t
    (lab? (read-text (string-append room "(aspace a (robot (pose 0 0 0)))"
                                    " (aspace b (robot (pose 1000 0 0))))"))))
  (test "a larger radius from the b14 clause counts" #t
    (says? (string-append room "(b14 (radius 600)) (aspace a (robot (pose 0 0 0)))"
                          " (aspace b (robot (pose 1000 0 0))))")
           "the robot b stands on the robot a"))
  (test "outside the walls of a rectangular room" #t
    (says? (string-append "(lab x (world (wall -3000 -3000 3000 -3000)"
                          " (wall 3000 -3000 3000 3000)"
                          " (wall 3000 3000 -3000 3000) (wall -3000 3000 -3000 -3000))\n"
                          "(aspace a (robot (pose 9000 0 0))))")
           (string-append ":2: (aspace a (robot (pose 9000 0 0))): the robot a stands"
                          " outside the walls")))
  (test "beside a lone wall is no room to be outside of" #t
    (lab? (read-text (string-append "(lab x (world (wall 0 0 1000 0))"
                                    " (aspace a (robot (pose 9000 0 0))))")))))

(test-group "every clause is checked, within aspace, robot, world, simulator, b14"
  (define (mistake name text what)
    (test name #t (says? text what)))
  (mistake "a misspelt clause of an address space, with the nearest"
           "(lab x\n  (aspace a\n    (capabilites camera)))"
           (string-append ":3: (capabilites camera): no such clause in aspace;"
                          " did you mean capabilities?"))
  (mistake "a misspelt setting of a robot"
           "(lab x (aspace a (robot (pose 0 0 0)\n (tetherd #f))))"
           ":2: (tetherd #f): no such clause in robot; did you mean tethered?")
  (mistake "a misspelt item of the world"
           "(lab x (world (bx 0 0 100 100 0)))"
           "(bx 0 0 100 100 0): no such clause in world; did you mean box?")
  (mistake "a coordinate that is no number"
           "(lab x (aspace a (robot (pose 1200 abc 180))))"
           "(pose 1200 abc 180): pose takes x y heading, three numbers")
  (mistake "a coordinate in quotes" "(lab x (aspace a (robot (pose \"1200\" 0 180))))"
           "pose takes x y heading")
  (mistake "a coordinate left out" "(lab x (aspace a (robot (pose 1200 -400))))"
           "(pose 1200 -400): pose takes x y heading")
  (mistake "a value of the wrong kind" "(lab x (aspace a (robot (battery \"full\"))))"
           "(battery \"full\"): battery takes volts, a positive number")
  (mistake "a wall of three numbers" "(lab x (world (wall 0 0 1000)))"
           "(wall 0 0 1000): wall takes x1 y1 x2 y2")
  (mistake "a box of negative depth" "(lab x (world (box 0 0 600 -600 0)))"
           "(box 0 0 600 -600 0): box takes x y width depth heading")
  (mistake "a box with no mass" "(lab x (world (box 0 0 600 600 0 0)))"
           "width, depth and mass above 0")
  (mistake "a wall with no thickness" "(lab x (world (wall 0 0 1000 0 0)))"
           "the thickness above 0")
  (mistake "a workstation's position" "(lab x (aspace a (position 0 0)))"
           "(position 0 0): position takes x y heading")
  (mistake "a scripted load" "(lab x (aspace a (load ((0 high)))))"
           "(load ((0 high))): load takes")
  (mistake "a simulator setting" "(lab x (simulator (speed slow)))"
           "(speed slow): speed takes a positive number, or fast")
  (mistake "a b14 setting" "(lab x (b14 (sonar-rays 20)))"
           "(sonar-rays 20): sonar-rays takes a whole number from 1 to 16")
  (mistake "a name longer than the simulator keeps"
           (string-append "(lab x (aspace " (make-string 64 #\a) "))")
           "an address space's name is at most 63 characters")
  (mistake "an item that is no clause" "(lab x (world wall))"
           "(world wall): wall is not a clause")
  (mistake "a missing ), named at the clause that lacks it"
           "(lab x\n  (timeout 3)\n  (aspace a (robot (pose 0 0 0))\n  (aspace b))\n"
           (string-append file ":3: this list has no closing ): the file ends inside it"))
  (mistake "the end of the file inside the last clause"
           "(lab x\n  (timeout 3)\n  (load 0.5" ":3: this list has no closing )")
  (mistake "a ) too many" "(lab x)\n)" ":2: a ) that closes nothing")
  (mistake "a datum the reader refuses, with what it refused"
           "(lab x\n  (timeout #\\xyzw))"
           ":2: cannot read this: unknown char name \"xyzw\"")
  (mistake "an empty file" "" (string-append file ": the file is empty"))
  (mistake "a file of comments only" "; nothing yet\n" "the file is empty")
  (mistake "two forms" "(lab x)\n(lab y)" ":2: (lab y): a second form")
  (test "a long clause is cut, to one line" #t
    (let ((message (read-text
                    (string-append "(lab x (aspace a (capabilities "
                                   "sonar ir bumpers speech buttons lights mobile"
                                   " camera) (colour blue)))"))))
      (and (text-contains? message "(colour blue): no such clause in aspace")
           (not (text-contains? message "\n")))))
  (test "a clause past 60 characters is cut at 56, with ..." #t
    (says? (string-append "(lab x (aspace a (capabilites sonar ir bumpers speech buttons"
                          " lights mobile camera)))")
           (string-append "(capabilites sonar ir bumpers speech buttons lights mobi ...:"
                          " no such clause")))
  (test "every example lab passes" '(#t #t #t #t)
    (map (lambda (f) (lab? (read-lab (tool-path (string-append "examples/" f)))))
         '("tulane-lab.scm" "box-lab.scm" "box-lab-right.scm" "box-lab-alone.scm"))))

(test-group "a file read again as it was is the same lab, and checked again"
  (test 7 (setting "(lab x (timeout 7))" 'timeout))
  (test 7 (lab-setting (read-lab file) 'timeout))
  (test 8 (setting "(lab x (timeout 8))" 'timeout))
  (call-with-output-file (string-append dir "/c.scm")
    (lambda (out) (write-string "(define y 1)\n" out)))
  (test #t (lab? (read-text "(lab x (code \"c.scm\"))")))
  (delete-file (string-append dir "/c.scm"))
  (test "a code file gone since" #t
    (let ((message (guard (e ((error-object? e) (error-object-message e)))
                     (read-lab file))))
      (and (string? message) (text-contains? message "no such file c.scm"))))
  (test "the same text at a line more" #t
    (says? "\n(lab x (aspace a (capabilites sonar)))" "lab.scm:2:")))

(test-end)
(delete-file-hierarchy dir)
(test-exit)

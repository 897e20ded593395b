;;;; Within aspace, robot, world, simulator and b14, part of (murdoch lab):
;;;; what each clause may hold, as the address spaces and sim/lab.c read
;;;; it: a reader for each name's values, a robot's in a table of their own.

(define (values-of n check what)
  (make-reader (lambda (xs) (and (= (length xs) n) (every check xs))) what))

(define (reals low high what)
  (make-reader (lambda (xs) (and (<= low (length xs) high) (every real? xs))) what))

(define (positive-real? x) (and (real? x) (positive? x)))

;; As reals, where the values at the places given, when there, are above 0:
;; a size or a mass (Box2D takes a negative one without a word).
(define (sized-reals low high places what)
  (make-reader (lambda (xs)
                 (and (<= low (length xs) high) (every real? xs)
                      (every (lambda (i)
                               (or (>= i (length xs)) (positive? (list-ref xs i))))
                             places)))
               what))

(define (non-negative? x) (and (real? x) (>= x 0)))
(define (port-number? x) (and (exact-integer? x) (< 0 x 65536)))

(define (load-value? x)
  (or (non-negative? x)
      (and (list? x) (pair? x)
           (every (lambda (p) (and (list? p) (= (length p) 2) (every non-negative? p)))
                  x))))

(define topic-name (values-of 1 string? "a ROS 2 topic name, in quotes"))

;; A robot reached through ROS 2 (docs/ros2.md): its trip server is
;; robot/ros2/trip_ros2.py, and the simulator makes no B14 for it.
(define ros2-table
  `((namespace . ,(values-of 1 string? "a ROS 2 namespace, in quotes, as \"/tb1\""))
    (cmd-vel . ,(values-of 1 (lambda (x) (memq x '(twist stamped))) "twist or stamped"))
    (cmd-vel-topic . ,topic-name)
    (odom . ,topic-name)
    (scan . ,topic-name)
    (range . ,(make-reader (lambda (xs) (and (<= 1 (length xs) 16) (every string? xs)))
                           "one to sixteen ROS 2 topic names, in quotes"))
    (battery . ,topic-name)
    (fiducials . ,topic-name)
    (appear-timeout . ,(values-of 1 positive-real? "a positive number of seconds"))
    (arrive-mm . ,(values-of 1 positive-real? "a positive number of millimetres"))
    (arrive-deg . ,(values-of 1 positive-real? "a positive number of degrees"))))

(define robot-table
  `((ros2 . ,ros2-table)
    (pose . ,(reals 3 3 "x y heading, three numbers (mm, mm, degrees)"))
    (tethered . ,(values-of 1 boolean? "#t or #f"))
    (battery . ,(values-of 1 positive-real? "volts, a positive number"))
    (trip-port . ,(values-of 1 port-number? "a port number"))
    (trip-host . ,(values-of 1 string? "an IPv4 address, in quotes"))))

(define aspace-table
  `((port . ,(values-of 1 port-number? "a port number"))
    (host . ,(values-of 1 string? "an IPv4 address, in quotes"))
    (robot . ,robot-table)
    (position . ,(reals 3 3 "x y heading, three numbers (mm, mm, degrees)"))
    (capabilities . ,(make-reader (lambda (xs) (every symbol? xs)) "subjects, as names"))
    (load . ,(values-of 1 load-value? "a number, or ((SECONDS LOAD) ...)"))))

(define world-table
  `((wall . ,(sized-reals 4 5 '(4) (string-append "x1 y1 x2 y2 and a thickness if not 50:"
                                                  " four or five numbers, the thickness"
                                                  " above 0")))
    (box . ,(sized-reals 5 6 '(2 3 5)
                         (string-append "x y width depth heading and a mass if not 5:"
                                        " five or six numbers, width, depth and mass"
                                        " above 0")))
    (friction . ,(values-of 1 non-negative? "a number"))))

(define simulator-table
  `((step-hz . ,(values-of 1 (lambda (x) (and (real? x) (>= x 1))) "a number from 1"))
    (seed . ,(values-of 1 real? "a number"))
    (speed . ,(values-of 1 (lambda (x) (or (positive-real? x) (eq? x 'fast)))
                          "a positive number, or fast"))
    (stall-timeout . ,(values-of 1 positive-real? "a positive number of seconds"))))

(define (increasing-pair)
  (make-reader (lambda (xs)
                 (and (= (length xs) 2) (every real? xs) (< (car xs) (cadr xs))))
               "two numbers, the first the smaller"))

(define b14-table
  `(,@(map (lambda (name) `(,name . ,(values-of 1 non-negative? "a number, 0 or more")))
           '(radius mass max-speed max-turn speed turn-speed sonar-cone sonar-noise
             sonar-hz ir-range fiducial-range battery-drain battery-idle battery-charge))
    (sonar-range . ,(increasing-pair))
    (battery-range . ,(increasing-pair))
    (fiducial-fov . ,(values-of 1 (lambda (x) (and (real? x) (< 0 x) (<= x 360)))
                                 "degrees, above 0 and at most 360"))
    (sonar-rays . ,(values-of 1 (lambda (x) (and (exact-integer? x) (<= 1 x 16)))
                               "a whole number from 1 to 16"))
    (max-frame . ,(values-of 1 (lambda (x) (and (exact-integer? x) (<= 64 x 65536)))
                              "a whole number from 64 to 65536"))))

(define (check-within path c items table)
  (for-each (lambda (item) (check-item path c item table)) items))

(define (check-item path outer item table)
  (cond
   ((not (and (pair? item) (symbol? (car item)) (list? item)))
    (lab-file-error path outer (string-append (clause-text item) " is not a clause"
                                              " (NAME VALUE ...)")))
   ((assq (car item) table)
    => (lambda (entry)
         (let ((reader (cdr entry)))
           (cond ((not (reader? reader)) (check-within path item (cdr item) reader))
                 ((not ((reader-read reader) (cdr item)))
                  (lab-file-error path item
                                  (string-append (symbol->string (car item))
                                                 " takes " (reader-what reader))))))))
   (else
    (lab-file-error path item
                    (string-append "no such clause in " (symbol->string (car outer))
                                   (did-you-mean (car item) (map car table)))))))

(define (check-inside path c)
  (case (car c)
    ((aspace)
     (if (not (and (pair? (cdr c)) (symbol? (cadr c))))
         (lab-file-error path c "an address space is (aspace NAME CLAUSE ...)"))
     (if (>= (string-length (symbol->string (cadr c))) 64)
         (lab-file-error path c "an address space's name is at most 63 characters"))
     (check-within path c (cddr c) aspace-table))
    ((world) (check-within path c (cdr c) world-table))
    ((simulator) (check-within path c (cdr c) simulator-table))
    ((b14) (check-within path c (cdr c) b14-table))))

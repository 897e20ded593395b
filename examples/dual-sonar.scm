;;; The dual-sonar task (thesis Figure 4.6); filled in with pose-task.
